// Helpers shared by the lib tests: constraint checks written independently of the solver.
#pragma once

#include <chaintube/chaintube.h>
#include <cmath>
#include <gtest/gtest.h>
#include <numbers>
#include <random>

namespace chaintube::test {

constexpr double kDegree = std::numbers::pi / 180.0;

inline HoseSpec paperSpec(int segments = 12, double expansion = 0.2, double deflectionDegrees = 40)
{
    HoseSpec spec;
    spec.outerDiameter = 0.02;
    spec.segmentCount = segments;
    spec.material.expansionCoefficient = expansion;
    spec.material.bendLimit = BendLimit::deflectionAngle(deflectionDegrees * kDegree);
    return spec;
}

/// A frame that only translates (world metres), as a part moved along a straight line.
inline Frame translated(const Vec3& by)
{
    Frame frame = Frame::identity();
    frame.translation = by;
    return frame;
}

/// Half the angle subtended by a circular arc whose chord is `ratio` times its length (chord
/// 2 R sin h, length 2 R h): the root of sin h = ratio · h, by Newton's method from 1.
inline double arcHalfAngle(double ratio)
{
    double half = 1.0;
    for (int i = 0; i < 50; ++i)
        half -= (std::sin(half) - ratio * half) / (std::cos(half) - ratio);
    return half;
}

/// Largest relative length excess and largest angle excess (radians), measured from scratch.
struct Violation
{
    double length = 0.0;
    double angle = 0.0;
};

inline Violation violation(const Hose& hose)
{
    Violation v;
    const std::vector<Vec3> p = hose.points();
    for (int s = 0; s + 1 < hose.pointCount(); ++s) {
        const double l = (p[s + 1] - p[s]).norm();
        v.length = std::max(v.length, std::max(l - hose.maxLength(s), hose.minLength(s) - l) /
                                          hose.restLength(s));
    }
    for (int j = 1; j + 1 < hose.pointCount(); ++j) {
        const Vec3 a = p[j] - p[j - 1], b = p[j + 1] - p[j];
        const double turn = std::atan2(a.cross(b).norm(), a.dot(b));
        v.angle = std::max(v.angle, turn - hose.deflectionLimit(j));
    }
    return v;
}

#define EXPECT_CONSTRAINTS_HOLD(hose, tolerance)                                                   \
    do {                                                                                           \
        const ::chaintube::test::Violation v_ = ::chaintube::test::violation(hose);                \
        EXPECT_LE(v_.length, tolerance) << "length band violated";                                 \
        EXPECT_LE(v_.angle, tolerance) << "deflection limit violated";                             \
    } while (0)

inline bool allFinite(const Hose& hose)
{
    for (const Vec3& p : hose.points())
        if (!p.allFinite()) return false;
    return true;
}

} // namespace chaintube::test
