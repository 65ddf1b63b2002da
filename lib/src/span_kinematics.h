// The span solver's kinematics, shared by its Newton solve (span_solver.cpp) and its steps
// towards a target beyond reach (span_reach.cpp): segment directions turned by Cayley rotations
// and clamped to their joints' bend limits, and the fixed-size row blocks of the goals. Internal
// to lib/.
#pragma once

#include "span_solver.h"

#include <Eigen/Dense>

namespace chaintube::detail {

/// SpanSolver::solve: m_lengthHeld, the end of its band a length is held at (0: free).
constexpr unsigned char kHeldAtMax = 1, kHeldAtMin = 2;
constexpr int kMaxRows = 16; // position blocks of 3 (goals and the end) and the end's bend row
using RowVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxRows, 1>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, kMaxRows>;

/// Rotates x by the Cayley rotation of ω (exactly orthogonal, first order the rotation vector).
[[gnu::always_inline]] inline Vec3 cayley(const Vec3& omega, const Vec3& x)
{
    const Vec3 a = 0.5 * omega;
    const double k = 2.0 / (1.0 + a.squaredNorm());
    const Vec3 ax = a.cross(x);
    return x + k * (ax + a.cross(ax));
}

/// Rotation matrix taking unit vector `from` to unit vector `to` about their common normal.
inline Mat3 rotationBetween(const Vec3& from, const Vec3& to)
{
    const Vec3 axis = from.cross(to);
    const double s = axis.norm(), c = from.dot(to);
    if (!(s > 1e-300)) return Mat3::Identity();
    const Vec3 u = axis / s;
    Mat3 k;
    k << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;
    return Mat3::Identity() + s * k + (1.0 - c) * k * k;
}

/// clampDirection's clamp of a direction beyond its limit (out of line: about one call of
/// clampDirection in twenty needs it in the real-time walks).
[[gnu::noinline]] inline void clampBeyondLimit(Vec3& ds, const Vec3* before, double cosLimit,
                                               double sinLimit, Mat3& correction, bool& corrected)
{
    const Vec3 unit = ds.normalized();
    const double c = before->dot(unit);
    Vec3 w = unit - c * *before;
    if (!(w.norm() > 1e-12)) w = anyPerpendicular(*before);
    const Vec3 clamped = (cosLimit * *before + sinLimit * w.normalized()).normalized();
    correction = rotationBetween(unit, clamped) * correction;
    corrected = true;
    ds = clamped;
}

/// Takes direction `ds` through the correction so far (the rotations of the joints clamped
/// before it) and clamps it to its limit against `before` (null: no limit), composing its own
/// clamp into the correction so that the rest of the chain turns with it (the joints after it
/// keep their turns). The corrections are built from unit vectors, so they are orthogonal and
/// the directions they turn stay unit to rounding.
[[gnu::always_inline]] inline void clampDirection(Vec3& ds, const Vec3* before, double cosLimit,
                                                  double sinLimit, Mat3& correction,
                                                  bool& corrected)
{
    if (corrected) ds = correction * ds;
    if (!before || !(cosLimit > -1.0 + 1e-12)) return;
    // before·ds ≥ cos·|ds|, without the square root where both sides are positive.
    const double dot = before->dot(ds);
    if (cosLimit >= 0.0 ? dot >= 0.0 && dot * dot >= cosLimit * cosLimit * ds.squaredNorm()
                        : dot >= cosLimit * ds.norm())
        return;
    clampBeyondLimit(ds, before, cosLimit, sinLimit, correction, corrected);
}

/// The cross-product matrix [a]: [a] x = a × x.
inline Mat3 skew(const Vec3& a)
{
    Mat3 k;
    k << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
    return k;
}

} // namespace chaintube::detail
