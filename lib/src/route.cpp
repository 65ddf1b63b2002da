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

std::vector<Vec3> filletRoute(const std::vector<Vec3>& route, double radius, double maxArcStep)
{
    if (!(radius >= 0.0) || !std::isfinite(radius))
        throw InvalidArgument("filletRoute: radius must be finite and >= 0");
    if (!(maxArcStep > 0.0) || !std::isfinite(maxArcStep))
        throw InvalidArgument("filletRoute: maxArcStep must be finite and > 0");
    std::vector<Vec3> points;
    for (const Vec3& p : route)
        if (points.empty() || (p - points.back()).norm() > 0.0) points.push_back(p);
    if (points.size() < 3 || radius == 0.0) return points;

    std::vector<Vec3> out{points.front()};
    for (size_t i = 1; i + 1 < points.size(); ++i) {
        const Vec3 &a = points[i - 1], &b = points[i], &c = points[i + 1];
        const double legIn = (b - a).norm(), legOut = (c - b).norm();
        const Vec3 d1 = (b - a) / legIn, d2 = (c - b) / legOut;
        const double cosTurn = std::clamp(d1.dot(d2), -1.0, 1.0);
        const double turn = std::acos(cosTurn);
        const Vec3 perpendicular = d2 - cosTurn * d1;
        if (turn < 1e-9 || perpendicular.norm() < 1e-12) {
            out.push_back(b); // straight (or an exact reversal, which no arc can round)
            continue;
        }
        const Vec3 inward = perpendicular.normalized();
        const double halfTan = std::tan(0.5 * turn);
        const double tangentLength = std::min(radius * halfTan, 0.5 * std::min(legIn, legOut));
        const double arcRadius = tangentLength / halfTan;
        const Vec3 arcStart = b - d1 * tangentLength;
        const Vec3 centre = arcStart + inward * arcRadius;
        const int steps = std::max(1, static_cast<int>(std::ceil(turn * arcRadius / maxArcStep)));
        for (int k = 0; k <= steps; ++k) {
            const double s = turn * k / steps;
            out.push_back(centre + arcRadius * (-inward * std::cos(s) + d1 * std::sin(s)));
        }
    }
    out.push_back(points.back());
    // Arcs that use exactly half of a leg meet the next arc: drop exact duplicates.
    std::vector<Vec3> unique{out.front()};
    for (size_t i = 1; i < out.size(); ++i)
        if ((out[i] - unique.back()).norm() > 1e-15 * (1.0 + out[i].norm()))
            unique.push_back(out[i]);
    return unique;
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
