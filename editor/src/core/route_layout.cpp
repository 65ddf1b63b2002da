#include "chaintube/editor/route_layout.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace chaintube::editor {

namespace {

/// Common hose outer diameters (metres): the sizes a default is rounded to.
constexpr std::array<double, 14> kCommonHoseDiameters = {0.002, 0.003, 0.004, 0.005, 0.006,
                                                         0.008, 0.010, 0.012, 0.016, 0.020,
                                                         0.025, 0.032, 0.040, 0.050};

bool usable(const Vec3& v)
{
    return v.allFinite() && v.squaredNorm() > 1e-300;
}

} // namespace

SurfaceOffset offsetFromSurface(const Vec3& surfacePoint, const Vec3& normal,
                                const Vec3& viewDirection, double distance)
{
    SurfaceOffset result;
    const bool haveView = usable(viewDirection);
    if (usable(normal)) {
        result.direction = normal.normalized();
        result.alongSurfaceNormal = true;
        // The side the click came from: the normal faces the camera, against the ray.
        if (haveView && result.direction.dot(viewDirection) > 0.0)
            result.direction = -result.direction;
    } else if (haveView) {
        result.direction = -viewDirection.normalized();
    } else {
        result.direction = Vec3::UnitY();
    }
    const double out = std::isfinite(distance) ? std::max(0.0, distance) : 0.0;
    result.position = surfacePoint + out * result.direction;
    return result;
}

double routePointDistance(double outerDiameter, double clearance)
{
    const double kept = std::isfinite(clearance) ? std::max(0.0, clearance) : 0.0;
    return 0.5 * outerDiameter + kept + kRouteClearanceMargin;
}

double defaultHoseDiameter(const Box& sceneBounds)
{
    if (sceneBounds.empty() || !sceneBounds.min.allFinite() || !sceneBounds.max.allFinite())
        return kFallbackHoseDiameter;
    const double diagonal = (sceneBounds.max - sceneBounds.min).norm();
    if (!(diagonal > 0.0) || !std::isfinite(diagonal)) return kFallbackHoseDiameter;
    const double wanted = diagonal * kHoseDiameterPerSceneDiagonal;
    // Nearest by ratio: |log(size / wanted)| smallest; sizes outside the list's range end at
    // its first or last entry, which is the clamp.
    double best = kCommonHoseDiameters.front();
    for (double size : kCommonHoseDiameters)
        if (std::abs(std::log(size / wanted)) < std::abs(std::log(best / wanted))) best = size;
    return best;
}

double defaultMinBendRadius(double outerDiameter)
{
    return kBendRadiusPerDiameter * outerDiameter;
}

int newHoseSegmentCount(double routeLength, double outerDiameter)
{
    const double segment =
        std::min(kMaxNewSegmentLength, 0.5 * defaultMinBendRadius(outerDiameter));
    if (!(routeLength > 0.0) || !(segment > 0.0) || !std::isfinite(routeLength / segment))
        return kMinNewSegmentCount;
    const double count = std::round(routeLength / segment);
    return static_cast<int>(
        std::clamp(count, double(kMinNewSegmentCount), double(kMaxNewSegmentCount)));
}

NewHoseMaterial newHoseMaterial(const Material& preset, double outerDiameter, double segmentLength)
{
    const double radius = preset.bendLimit.kind == BendLimit::Kind::MinBendRadius
                              ? preset.bendLimit.value
                              : bendRadiusOfTurn(segmentLength, preset.bendLimit.value);
    if (radius > 0.0 && radius >= kMinPresetBendRadiusPerDiameter * outerDiameter &&
        radius <= kMaxPresetBendRadiusPerDiameter * outerDiameter)
        return {preset, true};
    Material own = preset;
    own.bendLimit = BendLimit{BendLimit::Kind::MinBendRadius, defaultMinBendRadius(outerDiameter)};
    return {own, false};
}

} // namespace chaintube::editor
