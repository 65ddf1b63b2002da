// ChainTube — model only what a scene needs: the coarsest resolution that meets a tolerance.
#pragma once

#include "chaintube/material.h"

namespace chaintube {

/// Axis and ring resolution for a hose.
struct Resolution
{
    double segmentLength = 0.0; ///< metres: axis segment length (rest)
    int ringSides = 0;          ///< sides of a circular profile
    /// Bounds the choice guarantees (metres), for reports.
    double centrelineError = 0.0; ///< sagitta of a segment on the tightest allowed bend
    double ringError = 0.0;       ///< radius − apothem of the polygonal ring
};

/// The coarsest resolution whose geometric error stays within `tolerance` (metres > 0):
///  * Axis: on the tightest bend the material allows (radius R = minBendRadius), a chord of
///    length l deviates from the arc by the sagitta R − sqrt(R² − l²/4) ≤ tolerance, so
///    l = 2·sqrt(2Rt − t²) (for t ≥ R, l = 2R). Hoses with no bend limit (R = 0) use
///    R = outerRadius, the tightest bend a hose can physically take.
///  * Rings: an N-gon inscribed in radius r deviates by r(1 − cos(π/N)) ≤ tolerance, so
///    N = ceil(π / acos(1 − t/r)), at least 3 and at most 1024.
/// A DeflectionAngle limit has no physical radius: its radius is taken at the given
/// nominalSegmentLength (metres > 0). Throws InvalidArgument on non-finite or non-positive input.
Resolution resolutionFor(double tolerance, const BendLimit& bendLimit, double outerRadius,
                         double nominalSegmentLength = 0.01);

} // namespace chaintube
