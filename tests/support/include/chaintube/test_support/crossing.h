// The hose's axis crossing a collider: an independent check for the tunneling tests (lib and
// runtime). Header-only; the shapes are described by their planes, not by the library's meshes.
#pragma once

#include <algorithm>
#include <chaintube/types.h>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace chaintube::test_support {

enum class Kind { BoxPlate, TrianglePlate, KnifeEdge };

/// A convex solid as half-spaces n·p ≤ d in its local frame (the box plate, the wedge); the
/// two-triangle plate is the rectangle |x| ≤ hx, |y| ≤ hy in the plane z = 0.
struct Shape
{
    Kind kind = Kind::BoxPlate;
    double hx = 0.0, hy = 0.0;
    std::vector<std::pair<Vec3, double>> planes;
    std::vector<Vec3> positions;
    std::vector<std::uint32_t> indices;

    void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d)
    {
        indices.insert(indices.end(), {a, b, c, a, c, d});
    }
};

/// The box plate (|x| ≤ hx, |y| ≤ hy, |z| ≤ thickness / 2), the rectangle of two triangles
/// (z = 0) or the wedge (sharp edge along y at x = hx, 6 mm thick at x = −hx), with its triangles.
inline Shape makeShape(Kind kind, double hx, double hy, double thickness)
{
    Shape s;
    s.kind = kind;
    s.hx = hx;
    s.hy = hy;
    const double hz = 0.5 * thickness;
    switch (kind) {
    case Kind::BoxPlate: {
        for (int i = 0; i < 8; ++i)
            s.positions.emplace_back((i & 1) ? hx : -hx, (i & 2) ? hy : -hy, (i & 4) ? hz : -hz);
        s.quad(0, 2, 3, 1);
        s.quad(4, 5, 7, 6);
        s.quad(0, 1, 5, 4);
        s.quad(2, 6, 7, 3);
        s.quad(0, 4, 6, 2);
        s.quad(1, 3, 7, 5);
        for (int axis = 0; axis < 3; ++axis)
            for (const double sign : {-1.0, 1.0}) {
                Vec3 n = Vec3::Zero();
                n[axis] = sign;
                s.planes.emplace_back(n, axis == 0 ? hx : axis == 1 ? hy : hz);
            }
        break;
    }
    case Kind::TrianglePlate:
        s.positions = {{-hx, -hy, 0}, {hx, -hy, 0}, {hx, hy, 0}, {-hx, hy, 0}};
        s.quad(0, 1, 2, 3); // one-sided as wound; the collider treats it as a wall of no thickness
        break;
    case Kind::KnifeEdge: {
        // A wedge: the sharp edge along y at x = +hx, the back at x = −hx, 6 mm thick there.
        const double back = 0.003;
        s.positions = {{hx, -hy, 0}, {-hx, -hy, back}, {-hx, -hy, -back},
                       {hx, hy, 0},  {-hx, hy, back},  {-hx, hy, -back}};
        s.indices = {0, 1, 2, 3, 5, 4};
        s.quad(0, 3, 4, 1);
        s.quad(0, 2, 5, 3);
        s.quad(1, 4, 5, 2);
        const Vec3 up = Vec3(back, 0, 2 * hx).normalized(); // upper face: z ≤ back (hx − x)/2hx
        const Vec3 down(up.x(), 0, -up.z());
        s.planes.emplace_back(up, up.x() * hx);
        s.planes.emplace_back(down, down.x() * hx);
        s.planes.emplace_back(Vec3(-1, 0, 0), hx);
        s.planes.emplace_back(Vec3(0, 1, 0), hy);
        s.planes.emplace_back(Vec3(0, -1, 0), hy);
        break;
    }
    }
    return s;
}

/// Whether the straight path p0 → p1 (local) passes through the shape's interior shrunk by
/// `inset` (convex shapes), or through the rectangle shrunk by `inset` from one side of its
/// plane to the other (the two-triangle plate).
inline bool pathCrosses(const Shape& shape, const Vec3& p0, const Vec3& p1, double inset)
{
    if (shape.kind == Kind::TrianglePlate) {
        if (!(p0.z() * p1.z() < 0.0)) return false;
        const double t = p0.z() / (p0.z() - p1.z());
        const Vec3 x = p0 + t * (p1 - p0);
        return std::abs(x.x()) < shape.hx - inset && std::abs(x.y()) < shape.hy - inset;
    }
    double enter = 0.0, exit = 1.0;
    const Vec3 d = p1 - p0;
    for (const auto& [n, offset] : shape.planes) {
        const double denom = n.dot(d), room = offset - inset - n.dot(p0);
        if (std::abs(denom) < 1e-300) {
            if (room < 0.0) return false;
            continue;
        }
        const double t = room / denom;
        if (denom > 0.0)
            exit = std::min(exit, t);
        else
            enter = std::max(enter, t);
        if (enter > exit) return false;
    }
    return true;
}

/// Whether the hose's axis went through the collider during one frame: every axis point and
/// every millimetre along each segment moves in a straight line relative to the collider, from
/// where it was in the collider's previous frame to where it is in its new one (the sweeps'
/// own model of the motion), and none may pass through the collider (its interior shrunk by
/// the contact tolerance; for the plate of no thickness, its rectangle from one side to the
/// other).
inline bool axisCrossed(const Shape& shape, const std::vector<Vec3>& before,
                        const Frame& frameBefore, const std::vector<Vec3>& after,
                        const Frame& frameAfter, double tolerance)
{
    for (std::size_t s = 0; s + 1 < after.size(); ++s) {
        const Vec3 a0 = frameBefore.applyInverse(before[s]),
                   b0 = frameBefore.applyInverse(before[s + 1]);
        const Vec3 a1 = frameAfter.applyInverse(after[s]),
                   b1 = frameAfter.applyInverse(after[s + 1]);
        const double length = std::max((b0 - a0).norm(), (b1 - a1).norm());
        const int samples = 1 + static_cast<int>(std::ceil(length / 0.001));
        for (int k = 0; k <= samples; ++k) {
            const double u = double(k) / samples;
            if (pathCrosses(shape, a0 + u * (b0 - a0), a1 + u * (b1 - a1), tolerance)) return true;
        }
    }
    return false;
}

} // namespace chaintube::test_support
