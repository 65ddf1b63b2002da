#include "chaintube/resolution.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace chaintube {

Resolution resolutionFor(double tolerance, const BendLimit& bendLimit, double outerRadius,
                         double nominalSegmentLength)
{
    auto positive = [](double value, const char* name) {
        if (!std::isfinite(value) || value <= 0.0)
            throw InvalidArgument(std::string("resolutionFor: ") + name +
                                  " must be a finite length > 0 m, got " + std::to_string(value));
    };
    positive(tolerance, "tolerance");
    positive(outerRadius, "outerRadius");
    positive(nominalSegmentLength, "nominalSegmentLength");
    double radius = bendLimit.kind == BendLimit::Kind::MinBendRadius
                        ? bendLimit.value
                        : bendRadiusOfTurn(nominalSegmentLength, bendLimit.value);
    if (!(radius > 0.0)) radius = outerRadius;
    radius = std::max(radius, outerRadius);

    Resolution r;
    const double t = std::min(tolerance, radius);
    r.segmentLength = 2.0 * std::sqrt(std::max(0.0, 2.0 * radius * t - t * t));
    r.centrelineError =
        radius -
        std::sqrt(std::max(0.0, radius * radius - 0.25 * r.segmentLength * r.segmentLength));
    if (tolerance >= outerRadius) {
        r.ringSides = 3;
    } else {
        const double sides =
            std::ceil(std::numbers::pi / std::acos(1.0 - tolerance / outerRadius) - 1e-9);
        r.ringSides = static_cast<int>(std::clamp(sides, 3.0, 1024.0));
    }
    r.ringError = outerRadius * (1.0 - std::cos(std::numbers::pi / r.ringSides));
    return r;
}

} // namespace chaintube
