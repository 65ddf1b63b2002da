#include "chaintube/editor/route_layout.h"

#include "chaintube/route.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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

ClearedRoutePoint keepClearOfSurfaces(const SurfaceOffset& placed, double distance,
                                      const NearestSurfaceQuery& nearest)
{
    ClearedRoutePoint result;
    result.position = placed.position;
    if (!nearest || !std::isfinite(distance) || !(distance > 0.0) || !placed.position.allFinite()) {
        result.clear = true;
        result.clearance = std::isfinite(distance) ? std::max(0.0, distance) : 0.0;
        return result;
    }
    Vec3 position = placed.position;
    const Vec3 fallback = usable(placed.direction) ? placed.direction.normalized() : Vec3::UnitY();
    double bestClearance = -1.0;
    bool previous = false;
    Vec3 previousPoint = Vec3::Zero(), previousDirection = Vec3::Zero();
    for (int push = 0;; ++push) {
        const NearestSurface near = nearest(position, distance);
        const double clearance =
            near.found && near.point.allFinite() ? (position - near.point).norm() : distance;
        if (clearance > bestClearance) {
            bestClearance = clearance;
            result.position = position;
            result.clearance = std::min(clearance, distance);
        }
        if (clearance >= distance * (1.0 - 1e-12)) { // rounding of the last push
            result.clear = true;
            result.clearance = clearance;
            result.position = position;
            return result;
        }
        if (push == kMaxClearingPushes) return result;
        // Away from the nearest surface point by what is missing; from on the surface, along
        // the direction the point first went out.
        const Vec3 direction =
            clearance > 1e-12 * distance ? Vec3((position - near.point) / clearance) : fallback;
        const double missing = distance - clearance;
        // The previous push's surface, taken as its tangent plane, is kept where it is (or
        // brought to the distance too): both planes are solved at once, so an inner corner or
        // a wedge does not zig-zag between its faces. Opposite faces (a slot) are pushed from
        // one at a time.
        const double c = previous ? direction.dot(previousDirection) : 1.0;
        if (previous && std::abs(c) < 0.999) {
            const double missingThere =
                std::max(0.0, distance - previousDirection.dot(position - previousPoint));
            const double a = (missing - c * missingThere) / (1.0 - c * c);
            const double b = (missingThere - c * missing) / (1.0 - c * c);
            position += a * direction + b * previousDirection;
        } else {
            position += missing * direction;
        }
        previous = true;
        previousPoint = near.point;
        previousDirection = direction;
        result.pushes = push + 1;
    }
}

namespace {

/// The route leg (index of its first point) nearest to `point`.
size_t nearestLeg(const std::vector<Vec3>& route, const Vec3& point)
{
    size_t best = 0;
    double bestDistance = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i + 1 < route.size(); ++i) {
        const Vec3 leg = route[i + 1] - route[i];
        const double t = std::clamp((point - route[i]).dot(leg) / leg.squaredNorm(), 0.0, 1.0);
        const double d = (route[i] + t * leg - point).norm();
        if (d < bestDistance) {
            bestDistance = d;
            best = i;
        }
    }
    return best;
}

/// The axis point or segment middle nearest a surface within `distance`.
struct Nearest
{
    double clearance = 0.0;
    Vec3 at = Vec3::Zero();
    Vec3 surface = Vec3::Zero();
    bool found = false;
};

Nearest nearestToASurface(const std::vector<Vec3>& axis, double distance,
                          const NearestSurfaceQuery& nearest)
{
    Nearest worst;
    worst.clearance = distance;
    auto look = [&](const Vec3& at) {
        const NearestSurface near = nearest(at, distance);
        if (!near.found || !near.point.allFinite()) return;
        const double clearance = (at - near.point).norm();
        if (clearance < worst.clearance) worst = {clearance, at, near.point, true};
    };
    // The end points are route points, cleared when they were placed.
    for (size_t i = 1; i + 1 < axis.size(); ++i)
        look(axis[i]);
    for (size_t i = 0; i + 1 < axis.size(); ++i)
        look(0.5 * (axis[i] + axis[i + 1]));
    return worst;
}

/// How far the route's corners fall short of the bend radius: the sum over its tight corners
/// of 1 − the radius reached / `radius` (0 when every corner gets its arc).
double tightness(const std::vector<Vec3>& route, double radius)
{
    double sum = 0.0;
    for (const TightCorner& corner : tightCorners(route, radius))
        sum += 1.0 - corner.reachedRadius / radius;
    return sum;
}

} // namespace

ClearedRoute
keepRouteClearOfSurfaces(const std::vector<Vec3>& route, double distance, double bendRadius,
                         const std::function<std::vector<Vec3>(const std::vector<Vec3>&)>& axisOf,
                         const NearestSurfaceQuery& nearest)
{
    ClearedRoute result;
    result.route = route;
    for (size_t i = 0; i < route.size(); ++i)
        result.given.push_back(static_cast<int>(i));
    result.clearance = std::isfinite(distance) ? std::max(0.0, distance) : 0.0;
    result.clear = true;
    if (!nearest || !axisOf || route.size() < 2 || !(distance > 0.0) || !std::isfinite(distance))
        return result;
    ClearedRoute current = result;
    for (int round = 0;; ++round) {
        const Nearest worst = nearestToASurface(axisOf(current.route), distance, nearest);
        current.clearance = worst.found ? worst.clearance : distance;
        current.clear = !worst.found || worst.clearance >= distance * (1.0 - 1e-6);
        if (round == 0 || current.clearance > result.clearance) result = current;
        if (current.clear || round == kMaxAddedRoutePoints) return result;
        // A new route point there, pushed clear of the surface (and of any other near it).
        SurfaceOffset placed;
        placed.position = worst.at;
        placed.direction = worst.clearance > 1e-12 * distance
                               ? Vec3((worst.at - worst.surface) / worst.clearance)
                               : Vec3::UnitY();
        // With a margin: the legs to its neighbours cut the corner it goes round.
        const ClearedRoutePoint cleared =
            keepClearOfSurfaces(placed, kAddedRoutePointMargin * distance, nearest);
        const size_t leg = nearestLeg(current.route, cleared.position);
        const Vec3& a = current.route[leg];
        const Vec3& b = current.route[leg + 1];
        const double tooNear = 1e-3 * (b - a).norm();
        if ((cleared.position - a).norm() < tooNear || (cleared.position - b).norm() < tooNear)
            return result; // it would double a route point: nothing more to gain here
        std::vector<Vec3> longer = current.route;
        longer.insert(longer.begin() + std::ptrdiff_t(leg) + 1, cleared.position);
        // A point that leaves a corner no room for the bend radius would trade the clearance
        // for a kink: the clicks leave no room to go round here.
        if (tightness(longer, bendRadius) > tightness(current.route, bendRadius)) return result;
        current.route = std::move(longer);
        current.given.insert(current.given.begin() + std::ptrdiff_t(leg) + 1, -1);
        ++current.added;
    }
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
