// The taut shape of a hose pinned at both ends whose middle is pulled straight up beyond its
// reach: the reference of the speed-against-error report's ends-fixed-middle-grab scenario and
// of the library's test of a held target at the edge of the reach. Header-only, Eigen only.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace chaintube::test_support {

/// The ends at A = 0 and B = (span, 0, 0), the middle at the apex T = (span / 2, h, 0): from
/// each end a straight line tangent to a circle of radius `radius` whose top is T, then the arc
/// to T. h is where that shape is exactly as long as the hose (halfLength a half): one monotone
/// equation, solved by bisection.
struct TautSpan
{
    double span = 0.8, halfLength = 0.5, radius = 0.1;
    double apexHeight = 0.0, tangentLength = 0.0, lineAngle = 0.0;

    Eigen::Vector3d centre() const { return {0.5 * span, apexHeight - radius, 0.0}; }
    void geometry(double h, double& t, double& gamma) const
    {
        const double cx = 0.5 * span, cy = h - radius, d = std::hypot(cx, cy);
        t = std::sqrt(std::max(0.0, d * d - radius * radius));
        gamma = std::atan2(cy, cx) + std::asin(std::min(1.0, radius / d));
    }
    static TautSpan solve(double span, double halfLength, double radius)
    {
        TautSpan taut;
        taut.span = span, taut.halfLength = halfLength, taut.radius = radius;
        double lo = radius, hi = halfLength + radius;
        for (int k = 0; k < 200; ++k) {
            const double h = 0.5 * (lo + hi);
            double t = 0, gamma = 0;
            taut.geometry(h, t, gamma);
            (t + radius * gamma > halfLength ? hi : lo) = h;
        }
        taut.apexHeight = 0.5 * (lo + hi);
        taut.geometry(taut.apexHeight, taut.tangentLength, taut.lineAngle);
        return taut;
    }
    /// The point at rest arclength s from A along the first half (s ≤ halfLength).
    Eigen::Vector3d point(double s) const
    {
        if (s <= tangentLength)
            return s * Eigen::Vector3d(std::cos(lineAngle), std::sin(lineAngle), 0.0);
        const double psi = std::min(lineAngle, (s - tangentLength) / radius), a = lineAngle - psi;
        return centre() + radius * Eigen::Vector3d(-std::sin(a), std::cos(a), 0.0);
    }
    /// The point at rest arclength s of a hose of length `total` (either half; total is
    /// 2 · halfLength up to rounding).
    Eigen::Vector3d along(double s, double total) const
    {
        if (s <= 0.5 * total) return point(s);
        Eigen::Vector3d mirrored = point(total - s);
        mirrored.x() = span - mirrored.x();
        return mirrored;
    }
};

} // namespace chaintube::test_support
