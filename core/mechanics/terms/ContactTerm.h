#pragma once
// The probe: a rigid sphere pressing the outer walls through a penalty on the distance from its
// centre to each outer triangle (mechanics/Contact.h), with the derivatives with respect to the
// sphere's centre that force control and the probe's Schur step need. Units: µm, µN, pJ.

#include <limits>
#include <optional>

#include "mechanics/Contact.h"
#include "mechanics/EnergyTerm.h"

namespace tp {

struct Probe {
  Vec3 center = Vec3::Zero();  // µm
  double radius = 1.0;         // µm
};

class ContactTerm final : public EnergyTerm {
 public:
  explicit ContactTerm(const TermContext& c);
  std::string name() const override { return "probe contact"; }
  EnergyPart part() const override { return EnergyPart::Contact; }
  bool isLoad() const override { return true; }
  void bind(const MeshLayout& layout, int) override { layout_ = &layout; }
  double evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const override;
  double energy(const Points& x, double& magnitude) const override;

  void setProbe(const Probe& probe);
  void clearProbe() { probe_.reset(); }
  const std::optional<Probe>& probe() const { return probe_; }
  void setLaw(const ContactLaw& law) { law_ = law; }
  const ContactLaw& law() const { return law_; }

  /// See Model::contactClearance, Model::probeDistance, Model::contactStepBound.
  double clearance() const { return probe_ ? 0.5 * probe_->radius : 0.0; }
  double probeDistance(const Points& x) const;
  double stepBound(const Points& x, const Points& dx, const Vec3& dp) const;
  /// See Model::touchedTriangles.
  std::vector<int> touched(const Points& x) const;

 private:
  template <class Fn>
  void forNearTriangles(const Points& x, Fn&& fn) const;

  const CellComplex& cc_;
  const Topology& topo_;
  const MeshLayout* layout_ = nullptr;
  std::optional<Probe> probe_;
  ContactLaw law_;
};

}  // namespace tp
