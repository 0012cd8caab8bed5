// Every energy term Model assembles, in evaluation order. A new term: its file in this folder,
// its factory in Terms.h, and one line here.
#include "mechanics/terms/Terms.h"

namespace tp {

const std::vector<TermRegistration>& registeredTerms() {
  static const std::vector<TermRegistration> terms{
      {"membrane", makeMembraneTerm},
      {"Koiter bending", makeKoiterTerm},
      {"hinge bending", makeHingeTerm},
      {"linear bending", makeLinearBendingTerm},
      {"turgor pressure", makePressureTerm},
      {"probe contact", makeContactTerm},
      {"point forces", makePointForceTerm},
  };
  return terms;
}

}  // namespace tp
