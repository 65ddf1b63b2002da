#include "chaintube/route.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace chaintube {

double polylineLength(const std::vector<Vec3>& polyline)
{
    double length = 0.0;
    for (size_t i = 1; i < polyline.size(); ++i)
        length += (polyline[i] - polyline[i - 1]).norm();
    return length;
}

namespace {

/// The route without consecutive duplicate points.
std::vector<Vec3> distinctPoints(const std::vector<Vec3>& route)
{
    std::vector<Vec3> points;
    for (const Vec3& p : route)
        if (points.empty() || (p - points.back()).norm() > 0.0) points.push_back(p);
    return points;
}

/// A corner's turn (radians) and the tangent length an arc of `radius` needs there.
struct RouteCorner
{
    double turn = 0.0;
    double wanted = 0.0; ///< radius · tan(turn / 2); 0 for a straight corner or a reversal
    bool roundable = false;
};

std::vector<RouteCorner> cornersOf(const std::vector<Vec3>& points, double radius)
{
    std::vector<RouteCorner> corners(points.size());
    for (size_t i = 1; i + 1 < points.size(); ++i) {
        const Vec3 d1 = (points[i] - points[i - 1]).normalized();
        const Vec3 d2 = (points[i + 1] - points[i]).normalized();
        const double cosTurn = std::clamp(d1.dot(d2), -1.0, 1.0);
        RouteCorner& corner = corners[i];
        corner.turn = std::acos(cosTurn);
        // Straight, or an exact reversal, which no arc can round.
        corner.roundable = corner.turn >= 1e-9 && (d2 - cosTurn * d1).norm() >= 1e-12;
        if (corner.roundable) corner.wanted = radius * std::tan(0.5 * corner.turn);
    }
    return corners;
}

/// The tangent length each corner gets: what it wants where its legs have room for both
/// corners on them, else each leg shared in proportion to what its two corners want (an end
/// leg belongs to its one corner whole).
std::vector<double> tangentLengths(const std::vector<Vec3>& points,
                                   const std::vector<RouteCorner>& corners)
{
    const size_t n = points.size();
    std::vector<double> tangent(n, 0.0);
    for (size_t i = 1; i + 1 < n; ++i) {
        if (!corners[i].roundable) continue;
        auto share = [&](size_t other, double leg) {
            const double mine = corners[i].wanted;
            const double theirs = (other > 0 && other + 1 < n) ? corners[other].wanted : 0.0;
            return mine + theirs <= leg ? mine : leg * mine / (mine + theirs);
        };
        tangent[i] = std::min(share(i - 1, (points[i] - points[i - 1]).norm()),
                              share(i + 1, (points[i + 1] - points[i]).norm()));
    }
    return tangent;
}

} // namespace

std::vector<Vec3> filletRoute(const std::vector<Vec3>& route, double radius, double maxArcStep)
{
    if (!(radius >= 0.0) || !std::isfinite(radius))
        throw InvalidArgument("filletRoute: radius must be finite and >= 0");
    if (!(maxArcStep > 0.0) || !std::isfinite(maxArcStep))
        throw InvalidArgument("filletRoute: maxArcStep must be finite and > 0");
    const std::vector<Vec3> points = distinctPoints(route);
    if (points.size() < 3 || radius == 0.0) return points;

    const std::vector<RouteCorner> corners = cornersOf(points, radius);
    const std::vector<double> tangent = tangentLengths(points, corners);
    std::vector<Vec3> out{points.front()};
    for (size_t i = 1; i + 1 < points.size(); ++i) {
        const Vec3 &a = points[i - 1], &b = points[i], &c = points[i + 1];
        if (!corners[i].roundable || !(tangent[i] > 0.0)) {
            out.push_back(b);
            continue;
        }
        const Vec3 d1 = (b - a).normalized(), d2 = (c - b).normalized();
        const double turn = corners[i].turn;
        const Vec3 inward = (d2 - std::cos(turn) * d1).normalized();
        const double arcRadius = tangent[i] / std::tan(0.5 * turn);
        const Vec3 arcStart = b - d1 * tangent[i];
        const Vec3 centre = arcStart + inward * arcRadius;
        const int steps = std::max(1, static_cast<int>(std::ceil(turn * arcRadius / maxArcStep)));
        for (int k = 0; k <= steps; ++k) {
            const double s = turn * k / steps;
            out.push_back(centre + arcRadius * (-inward * std::cos(s) + d1 * std::sin(s)));
        }
    }
    out.push_back(points.back());
    // Arcs that share a leg exactly meet there: drop exact duplicates.
    std::vector<Vec3> unique{out.front()};
    for (size_t i = 1; i < out.size(); ++i)
        if ((out[i] - unique.back()).norm() > 1e-15 * (1.0 + out[i].norm()))
            unique.push_back(out[i]);
    return unique;
}

std::vector<TightCorner> tightCorners(const std::vector<Vec3>& route, double radius)
{
    std::vector<TightCorner> tight;
    if (!(radius > 0.0) || !std::isfinite(radius)) return tight;
    // Indices into the route as given: distinct points keep their first index.
    std::vector<int> index;
    std::vector<Vec3> points;
    for (size_t i = 0; i < route.size(); ++i)
        if (points.empty() || (route[i] - points.back()).norm() > 0.0) {
            points.push_back(route[i]);
            index.push_back(static_cast<int>(i));
        }
    if (points.size() < 3) return tight;
    const std::vector<RouteCorner> corners = cornersOf(points, radius);
    const std::vector<double> tangent = tangentLengths(points, corners);
    for (size_t i = 1; i + 1 < points.size(); ++i) {
        const RouteCorner& corner = corners[i];
        if (corner.turn < 1e-9) continue;
        const double reached = corner.roundable ? tangent[i] / std::tan(0.5 * corner.turn) : 0.0;
        if (reached < radius * (1.0 - 1e-9)) tight.push_back({index[i], reached, corner.turn});
    }
    return tight;
}

std::vector<Vec3> resampleByArcLength(const std::vector<Vec3>& polyline, int segments)
{
    if (segments < 1) throw InvalidArgument("resampleByArcLength: segments must be >= 1");
    const double total = polylineLength(polyline);
    if (polyline.size() < 2 || !(total > 0.0))
        throw InvalidArgument("resampleByArcLength: the polyline has no length");
    std::vector<Vec3> out;
    out.reserve(static_cast<size_t>(segments) + 1);
    out.push_back(polyline.front());
    size_t leg = 0;
    double legStart = 0.0;
    double legLength = (polyline[1] - polyline[0]).norm();
    for (int k = 1; k < segments; ++k) {
        const double s = total * k / segments;
        while (legStart + legLength < s && leg + 2 < polyline.size()) {
            legStart += legLength;
            ++leg;
            legLength = (polyline[leg + 1] - polyline[leg]).norm();
        }
        const double t = legLength > 0.0 ? std::clamp((s - legStart) / legLength, 0.0, 1.0) : 0.0;
        out.push_back(polyline[leg] + t * (polyline[leg + 1] - polyline[leg]));
    }
    out.push_back(polyline.back());
    return out;
}

} // namespace chaintube
