#pragma once
// Raw AFM force curves: the text export of JPK's data-processing software (one force curve:
// `# key: value` header lines, then segments — extend, pause, retract — each with its own
// `# columns:` and `# units:` lines and whitespace-separated rows), and the conversion of any
// approach curve (piezo height and force) to indentation and force.
//
// Conversion (as AFM tools do it, e.g. nanite): the baseline — a straight line in height fitted
// to the first part of the approach, far from the sample — is subtracted from the force (the
// offset and tilt of the deflection signal); the contact point is where the corrected force last
// rises from the baseline's noise for good (the last point, scanning back from the deepest one,
// at or below zero before the force exceeds `thresholdSigma` times the baseline's standard
// deviation); the indentation is δ = (h_c − h) − F/k: the piezo's travel past contact less the
// cantilever's deflection (height h decreasing towards the sample, as JPK records it).
// Units out: µm and µN (1 N/m = 1 µN/µm).

#include <optional>
#include <string>
#include <vector>

#include "io/MeasuredCurve.h"

namespace tp {

struct RawCurveOptions {
  double baselineFraction = 0.4;  // of the approach's points (from the far end) for the baseline
  double thresholdSigma = 5.0;    // the force must exceed this many baseline deviations
  std::optional<double> contactHeight;  // µm: the user's contact point, instead of the estimate
};

/// What the conversion found, to be shown (and moved) by the user.
struct RawCurveReading {
  MeasuredCurve curve;       // indentation from the contact point (µm, ≥ 0) and force (µN)
  double contactHeight = 0;  // µm, piezo height at contact
  bool contactEstimated = true;
  double baselineOffset = 0;          // µN at height 0
  double baselineSlope = 0;           // µN/µm
  double noise = 0;                   // µN, standard deviation of the force about the baseline
  double springConstant = 0;          // µN/µm (= N/m)
  std::vector<double> height, force;  // the approach as read (µm, µN, baseline not removed)
};

/// Converts an approach (heights in µm decreasing towards the sample, forces in µN) with a
/// cantilever of `springConstant` (µN/µm). Throws std::runtime_error naming `name` when there
/// are too few points, no rise above the noise, or a contact height outside the data.
RawCurveReading indentationFromApproach(const std::vector<double>& height,
                                        const std::vector<double>& force, double springConstant,
                                        const std::string& name,
                                        const RawCurveOptions& options = {});

/// True when the text starts like a JPK text export ("# TEXT EXPORT", or segment headers).
bool looksLikeJpkText(const std::string& text);

/// Reads the extend segment of a JPK text export (height: `measuredHeight`, else `height`;
/// force: `vDeflection` in N, or in V or m converted with the header's sensitivity and spring
/// constant) and converts it. Throws std::runtime_error naming the file and line.
RawCurveReading parseJpkForceCurve(const std::string& text, const std::string& name,
                                   const RawCurveOptions& options = {});
RawCurveReading readJpkForceCurve(const std::string& path, const RawCurveOptions& options = {});

}  // namespace tp
