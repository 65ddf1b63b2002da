// Collision with scene objects and clearance.
#include "test_util.h"

#include <chaintube/collision.h>
#include <chrono>
#include <cstdio>
#include <numbers>

namespace chaintube::test {
namespace {

struct Mesh
{
    std::vector<Vec3> positions;
    std::vector<std::uint32_t> indices;

    void quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
    {
        const auto base = static_cast<std::uint32_t>(positions.size());
        positions.insert(positions.end(), {a, b, c, d});
        indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    /// Axis-aligned box min … max (12 triangles).
    void box(const Vec3& lo, const Vec3& hi)
    {
        auto corner = [&](int i) {
            return Vec3((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(),
                        (i & 4) ? hi.z() : lo.z());
        };
        const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                 {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (const auto& f : faces)
            quad(corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3]));
    }
    /// A wall of zero thickness in the plane x = x0 over y, z in [lo, hi].
    void wallX(double x0, double yLo, double yHi, double zLo, double zHi)
    {
        quad({x0, yLo, zLo}, {x0, yHi, zLo}, {x0, yHi, zHi}, {x0, yLo, zHi});
    }
    std::shared_ptr<MeshCollider> collider(const Frame& frame = Frame::identity()) const
    {
        return MeshCollider::fromArrays(positions, indices, frame);
    }
};

/// Distance from p to the mesh by brute force over every triangle (independent of the BVH:
/// dense barycentric sampling is too coarse, so this uses the closed-form projection).
double bruteForceDistance(const Mesh& mesh, const Frame& frame, const Vec3& world)
{
    const Vec3 p = frame.applyInverse(world);
    double best = std::numeric_limits<double>::infinity();
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
        const Vec3 a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
                   c = mesh.positions[mesh.indices[t + 2]];
        // Minimise over the triangle by projecting onto the plane and, if outside, the edges.
        const Vec3 n = (b - a).cross(c - a).normalized();
        const Vec3 onPlane = p - n * n.dot(p - a);
        const auto inside = [&](const Vec3& x) {
            return (b - a).cross(x - a).dot(n) >= 0 && (c - b).cross(x - b).dot(n) >= 0 &&
                   (a - c).cross(x - c).dot(n) >= 0;
        };
        if (inside(onPlane)) {
            best = std::min(best, (p - onPlane).norm());
            continue;
        }
        for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
            const double s = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
            best = std::min(best, (p - (u + s * (v - u))).norm());
        }
    }
    return best;
}

/// Smallest distance between the hose axis (sampled every 1 mm along each segment) and the
/// mesh, minus the hose radius: the surface clearance, measured independently of the solver.
double sampledClearance(const Hose& hose, const MeshCollider& collider)
{
    double best = std::numeric_limits<double>::infinity();
    for (int s = 0; s < hose.segmentCount(); ++s) {
        const Vec3 a = hose.point(s), b = hose.point(s + 1);
        const int samples = std::max(2, static_cast<int>((b - a).norm() / 0.001));
        for (int k = 0; k <= samples; ++k) {
            const MeshCollider::Closest c =
                collider.closestToPoint(a + (b - a) * (double(k) / samples));
            best = std::min(best, c.distance);
        }
    }
    return best - hose.outerRadius();
}

Hose straightHose(int segments = 20, double length = 1.0, const Vec3& start = Vec3::Zero())
{
    HoseSpec spec = paperSpec(segments, 0.2, 40);
    Hose hose = Hose::straight(start, Vec3::UnitX(), length, spec);
    hose.attach(0, 1, Frame::identity());
    return hose;
}

// --- the collider's queries -------------------------------------------------------------------

TEST(MeshCollider, ClosestPointMatchesBruteForceAndFollowsTheFrame)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Mesh mesh;
    for (int t = 0; t < 200; ++t) {
        const Vec3 centre(u(rng), u(rng), u(rng));
        const auto base = static_cast<std::uint32_t>(mesh.positions.size());
        for (int k = 0; k < 3; ++k)
            mesh.positions.push_back(centre + 0.2 * Vec3(u(rng), u(rng), u(rng)));
        mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    }
    Frame frame;
    frame.rotation = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
    frame.translation = Vec3(10, -3, 5);
    auto collider = mesh.collider(frame);
    EXPECT_EQ(collider->triangleCount(), 200);
    for (int q = 0; q < 300; ++q) {
        const Vec3 world = frame.apply(1.5 * Vec3(u(rng), u(rng), u(rng)));
        const MeshCollider::Closest c = collider->closestToPoint(world);
        ASSERT_TRUE(c.found);
        EXPECT_NEAR(c.distance, bruteForceDistance(mesh, frame, world), 1e-12);
        EXPECT_NEAR((c.onMesh - world).norm(), c.distance, 1e-12);
    }
    // Moving the frame moves the answer rigidly, no rebuild.
    const Vec3 query = frame.apply(Vec3(0.3, 0.2, -0.4));
    const MeshCollider::Closest before = collider->closestToPoint(query);
    Frame moved = frame;
    moved.translation += Vec3(0.5, 0, 0);
    ASSERT_TRUE(collider->setFrame(moved));
    const MeshCollider::Closest after = collider->closestToPoint(query + Vec3(0.5, 0, 0));
    EXPECT_NEAR(after.distance, before.distance, 1e-12);
    EXPECT_LT((after.onMesh - before.onMesh - Vec3(0.5, 0, 0)).norm(), 1e-12);
}

TEST(MeshCollider, SegmentQueriesAgreeWithDenseSamplingAndSeeCrossings)
{
    Mesh mesh;
    mesh.box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
    auto collider = mesh.collider();
    // Crossing a face: distance 0.
    const MeshCollider::Closest crossing = collider->closestToSegment({0, 0, -2}, {0, 0, 2});
    ASSERT_TRUE(crossing.found);
    EXPECT_EQ(crossing.distance, 0.0);
    // Passing a corner diagonally: against 10,000 samples along the segment.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.2, 1.2);
    for (int q = 0; q < 50; ++q) {
        const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
        const MeshCollider::Closest c = collider->closestToSegment(a, b);
        double sampled = std::numeric_limits<double>::infinity();
        for (int k = 0; k <= 10000; ++k)
            sampled = std::min(
                sampled, bruteForceDistance(mesh, Frame::identity(), a + (b - a) * (k / 10000.0)));
        EXPECT_LE(c.distance, sampled + 1e-12);
        EXPECT_GE(c.distance, sampled - (b - a).norm() / 10000.0 - 1e-12);
    }
}

TEST(MeshCollider, SphereSweepStopsAtAThinWallWithTheRadiusLeft)
{
    Mesh mesh;
    mesh.wallX(1.0, -1, 1, -1, 1);
    auto collider = mesh.collider();
    const MeshCollider::Sweep s = collider->sweepSphere({0, 0.1, 0}, {2, 0.1, 0}, 0.05);
    ASSERT_TRUE(s.hit);
    EXPECT_NEAR(s.fraction * 2.0, 0.95, 1e-12);
    EXPECT_NEAR(s.normal.x(), -1.0, 1e-12);
    // From the other side too (the wall has no back face).
    const MeshCollider::Sweep back = collider->sweepSphere({2, 0, 0}, {0, 0, 0}, 0.05);
    ASSERT_TRUE(back.hit);
    EXPECT_NEAR(2.0 - back.fraction * 2.0, 1.05, 1e-12);
}

TEST(MeshCollider, SphereRestingOnASurfaceSlidesAndLiftsOffButCannotSinkIn)
{
    Mesh mesh;
    mesh.quad({-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1});
    auto collider = mesh.collider();
    EXPECT_FALSE(collider->sweepSphere({0, 0.05, 0}, {0.5, 0.05, 0}, 0.05).hit);      // slide
    EXPECT_FALSE(collider->sweepSphere({0, 0.0499999, 0}, {0.5, 0.06, 0}, 0.05).hit); // lift off
    const MeshCollider::Sweep sink = collider->sweepSphere({0, 0.05, 0}, {0.5, 0.0, 0}, 0.05);
    ASSERT_TRUE(sink.hit);
    EXPECT_EQ(sink.fraction, 0.0);
}

TEST(MeshCollider, SphereCannotPassAGapNarrowerThanItsDiameter)
{
    for (const double gap : {0.015, 0.03}) {
        Mesh mesh;
        mesh.wallX(1.0, -1, -gap / 2, -1, 1);
        mesh.wallX(1.0, gap / 2, 1, -1, 1);
        auto collider = mesh.collider();
        const MeshCollider::Sweep s = collider->sweepSphere({0, 0, 0}, {2, 0, 0}, 0.01);
        EXPECT_EQ(s.hit, gap < 0.02) << "gap " << gap;
        if (s.hit) {
            // Touches the slot's edges, short of the wall plane.
            EXPECT_LT(s.fraction * 2.0, 1.0);
            EXPECT_NEAR(s.fraction * 2.0, 1.0 - std::sqrt(0.01 * 0.01 - gap * gap / 4), 1e-9);
        }
    }
}

TEST(MeshCollider, SegmentSweepStopsAKnifeEdgeBetweenTheEndsWithinItsQueryBound)
{
    // A wall of no thickness in the plane x = 0 whose edge runs along z at y = 0.03; a segment
    // across it (x from −0.05 to 0.05) moves 0.1 m along +y: its ends pass the wall 5 cm away,
    // its middle hits the edge.
    Mesh mesh;
    mesh.wallX(0.0, 0.03, 1.0, -1, 1);
    auto wall = mesh.collider();
    const Vec3 a0(-0.05, 0, 0), b0(0.05, 0, 0), move(0, 0.1, 0);
    EXPECT_FALSE(wall->sweepSphere(a0, a0 + move, 0.01).hit) << "the ends alone miss it";
    const MeshCollider::SegmentSweep s = wall->sweepSegment(a0, b0, a0 + move, b0 + move, 0.005);
    ASSERT_TRUE(s.hit);
    EXPECT_FALSE(s.bounded);
    EXPECT_LE(s.queries, MeshCollider::kSegmentSweepQueries);
    EXPECT_NEAR(s.fraction, 0.25, 0.02 * 0.005 / 0.1 + 1e-12) << "(0.03 − 0.005) / 0.1";
    const double at =
        wall->closestToSegment(a0 + s.fraction * move, b0 + s.fraction * move).distance;
    EXPECT_GE(at, 0.005 * (1 - 1e-12));
    EXPECT_NEAR(s.normal.y(), -1.0, 1e-9) << "from the edge back towards the segment";
    // Moving away, or along the wall beside it, nothing is hit; nor when nothing moves.
    EXPECT_FALSE(wall->sweepSegment(a0, b0, a0 - move, b0 - move, 0.005).hit);
    EXPECT_FALSE(wall->sweepSegment(a0, b0, a0, b0, 0.005).hit);
    // One query only: the move stops where that query proved safe, reported as bounded.
    const MeshCollider::SegmentSweep one =
        wall->sweepSegment(a0, b0, a0 + move, b0 + move, 0.005, 1);
    EXPECT_TRUE(one.hit);
    EXPECT_EQ(one.queries, 1);
    EXPECT_LE(one.fraction, s.fraction + 1e-12);
    // Starting 2 mm from the edge (inside the 5 mm guard), it keeps half of that.
    const Vec3 near(0, 0.028, 0);
    const MeshCollider::SegmentSweep close =
        wall->sweepSegment(a0 + near, b0 + near, a0 + near + move, b0 + near + move, 0.005);
    ASSERT_TRUE(close.hit);
    EXPECT_NEAR(0.002 - close.fraction * 0.1, 0.001, 0.02 * 0.001 + 1e-12);
    // Random segments and moves: every sampled point of the move up to the stop keeps the guard.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int q = 0; q < 200; ++q) {
        const Vec3 p0(0.05 * u(rng), 0.1 * u(rng) - 0.05, 0.05 * u(rng));
        const Vec3 p1(0.05 * u(rng), 0.1 * u(rng) - 0.05, 0.05 * u(rng));
        const Vec3 d(0.02 * u(rng), 0.1 * u(rng) + 0.05, 0.02 * u(rng));
        const double start = wall->closestToSegment(p0, p1).distance;
        const MeshCollider::SegmentSweep r = wall->sweepSegment(p0, p1, p0 + d, p1 + d, 0.004);
        const double guard = std::min(0.004, 0.5 * start);
        // Every sampled point of the move up to the stop keeps the guard.
        for (int k = 0; k <= 20; ++k) {
            const double t = r.fraction * k / 20.0;
            EXPECT_GE(wall->closestToSegment(p0 + t * d, p1 + t * d).distance, guard * (1 - 1e-9))
                << q;
        }
        if (!r.hit) {
            EXPECT_EQ(r.fraction, 1.0);
        }
    }
}

TEST(MeshCollider, RaycastFindsTheNearestTriangleFromEitherSide)
{
    Mesh mesh;
    mesh.box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
    Frame frame;
    frame.translation = Vec3(0, 0, 3);
    auto collider = mesh.collider(frame);
    const MeshCollider::RayHit hit = collider->raycast({0, 0, 0}, {0, 0, 1});
    ASSERT_TRUE(hit.hit);
    EXPECT_NEAR(hit.t, 2.5, 1e-12);
    EXPECT_NEAR(hit.normal.z(), -1.0, 1e-12);
    EXPECT_FALSE(collider->raycast({0, 0, 0}, {0, 0, 1}, 2.4).hit);
    EXPECT_FALSE(collider->raycast({0, 2, 0}, {0, 0, 1}).hit);
}

TEST(MeshCollider, BadArraysAreRefusedNamingTheField)
{
    const std::vector<Vec3> positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    auto message = [&](const std::vector<Vec3>& p, const std::vector<std::uint32_t>& i) {
        try {
            MeshCollider::fromArrays(p, i);
        } catch (const InvalidArgument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(
        message(positions, {0, 1}).find("collider indices: expected a non-zero multiple of 3"),
        std::string::npos);
    EXPECT_NE(
        message(positions, {0, 1, 3}).find("collider indices[2] = 3: expected < vertex count 3"),
        std::string::npos);
    EXPECT_NE(message({}, {0, 1, 2}).find("collider positions"), std::string::npos);
    EXPECT_NE(message({{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}}, {0, 1, 2})
                  .find("collider positions[2]: expected finite"),
              std::string::npos);
    const float flat[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::uint32_t idx[3] = {0, 1, 2};
    EXPECT_EQ(MeshCollider::fromArrays(flat, 3, idx, 3)->triangleCount(), 1);
    EXPECT_THROW(MeshCollider::fromArrays(flat, 3, nullptr, 3), InvalidArgument);
    Frame bad;
    bad.translation.x() = std::numeric_limits<double>::infinity();
    EXPECT_THROW(MeshCollider::fromArrays(positions, {0, 1, 2}, bad), InvalidArgument);
    auto collider = MeshCollider::fromArrays(positions, {0, 1, 2});
    EXPECT_FALSE(collider->setFrame(bad));
    EXPECT_TRUE(collider->frame().translation.allFinite());
}

TEST(MeshCollider, DegenerateMeshesStillFindEveryContact)
{
    // (1) 20,000 triangles at one spot (identical centroids), one of them differently shaped
    // and nearest to the queries; (2) a 1 m long, 1 µm wide strip of 40,000 slivers; (3) both
    // with a far outlier. Every query agrees with brute force: no subtree is skipped.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Mesh stacked;
    for (int t = 0; t < 20000; ++t) {
        const double s = 0.01 + 0.001 * (t % 7);
        const auto base = static_cast<std::uint32_t>(stacked.positions.size());
        // Centroid (0, 0, 0) for every triangle; the one with index 12345 reaches out to y = 0.3.
        const double reach = t == 12345 ? 0.3 : s;
        stacked.positions.insert(
            stacked.positions.end(),
            {Vec3(-s, -reach / 2, 0), Vec3(s, -reach / 2, 0), Vec3(0, reach, 0)});
        stacked.indices.insert(stacked.indices.end(), {base, base + 1, base + 2});
    }
    stacked.positions.insert(stacked.positions.end(),
                             {Vec3(50, 0, 0), Vec3(51, 0, 0), Vec3(50, 1, 0)});
    stacked.indices.insert(stacked.indices.end(), {20000 * 3, 20000 * 3 + 1, 20000 * 3 + 2});
    auto stackedCollider = stacked.collider();
    const MeshCollider::Closest top = stackedCollider->closestToPoint({0, 0.5, 0.01});
    ASSERT_TRUE(top.found);
    EXPECT_EQ(top.triangle, 12345);
    EXPECT_NEAR(top.distance, std::hypot(0.2, 0.01), 1e-12);
    const MeshCollider::RayHit down = stackedCollider->raycast({0, 0.25, 1}, {0, 0, -1});
    ASSERT_TRUE(down.hit) << "only the reaching triangle covers (0, 0.25)";
    EXPECT_EQ(down.triangle, 12345);
    const MeshCollider::Sweep sweep =
        stackedCollider->sweepSphere({0, 0.25, 1}, {0, 0.25, -1}, 0.01);
    ASSERT_TRUE(sweep.hit);
    EXPECT_NEAR(sweep.fraction, 0.99 / 2.0, 1e-9);
    const MeshCollider::Closest far = stackedCollider->closestToSegment({49, 2, 0}, {52, 2, 0});
    ASSERT_TRUE(far.found);
    EXPECT_EQ(far.triangle, 20000);
    EXPECT_NEAR(far.distance, 1.0, 1e-12);

    Mesh strip;
    const int slivers = 40000;
    for (int t = 0; t <= slivers; ++t) {
        const double x = double(t) / slivers;
        strip.positions.emplace_back(x, 0.0, 0.0);
        strip.positions.emplace_back(x, 1e-6, 0.0);
    }
    for (int t = 0; t < slivers; ++t) {
        const auto v = static_cast<std::uint32_t>(2 * t);
        strip.indices.insert(strip.indices.end(), {v, v + 2, v + 3, v, v + 3, v + 1});
    }
    auto stripCollider = strip.collider();
    for (int q = 0; q < 200; ++q) {
        const Vec3 p(1.2 * u(rng), 0.05 * u(rng), 0.05 * u(rng));
        const MeshCollider::Closest c = stripCollider->closestToPoint(p);
        ASSERT_TRUE(c.found);
        // The strip is (nearly) the segment x ∈ [0, 1] on the x axis, 1 µm wide in y.
        const double x = std::clamp(p.x(), 0.0, 1.0), y = std::clamp(p.y(), 0.0, 1e-6);
        EXPECT_NEAR(c.distance, (p - Vec3(x, y, 0)).norm(), 1e-12) << q;
        const MeshCollider::RayHit hit = stripCollider->raycast(Vec3(p.x(), 5e-7, 1), {0, 0, -1});
        EXPECT_EQ(hit.hit, p.x() >= 0.0 && p.x() <= 1.0) << q;
    }
}

// --- hoses staying outside ----------------------------------------------------------------------

TEST(HoseCollision, NoCollidersAndFarCollidersChangeNothing)
{
    Hose plain = straightHose(), far = straightHose();
    Mesh mesh;
    mesh.box({50, 50, 50}, {51, 51, 51});
    far.setColliders({mesh.collider()});
    for (int step = 1; step <= 20; ++step) {
        const Vec3 target(1.0 - 0.02 * step, 0.03 * step, 0.01 * step);
        const UpdateResult a = plain.grab(15, target), b = far.grab(15, target);
        EXPECT_EQ(a.status, b.status);
        EXPECT_FALSE(b.blocked);
        EXPECT_EQ(b.contacts, 0);
        for (int i = 0; i < plain.pointCount(); ++i)
            ASSERT_EQ(plain.point(i), far.point(i));
    }
}

TEST(HoseCollision, ThinWallStopsTheGrabbedEndAndReportsBlocked)
{
    for (const int steps : {1, 25}) {
        Hose hose = straightHose();
        Mesh mesh;
        mesh.wallX(1.05, -1, 1, -1, 1);
        auto wall = mesh.collider();
        hose.setColliders({wall});
        UpdateResult r;
        for (int s = 1; s <= steps; ++s)
            r = hose.grab(20, Vec3(1.0 + 0.1 * s / steps, 0, 0));
        EXPECT_TRUE(r.blocked);
        EXPECT_EQ(r.status, Status::Clamped);
        EXPECT_NEAR(hose.point(20).x(), 1.05 - hose.outerRadius(), 1e-4);
        EXPECT_NEAR(r.grabError, (hose.point(20) - Vec3(1.1, 0, 0)).norm(), 1e-12);
        EXPECT_GE(sampledClearance(hose, *wall), -1e-4);
        const Violation v = violation(hose);
        EXPECT_LE(v.length, 1e-6);
        EXPECT_LE(v.angle, 1e-6);
        for (int i = 0; i < hose.pointCount(); ++i)
            EXPECT_LT(hose.point(i).x(), 1.05);
    }
}

TEST(HoseCollision, HosePulledThroughAGapNarrowerThanItsDiameterIsBlockedAndNeverTunnels)
{
    for (const int steps : {1, 40}) {
        Hose hose = straightHose();
        const double gap = 0.015; // hose diameter 0.02
        Mesh mesh;
        mesh.wallX(1.05, -1, -gap / 2, -1, 1);
        mesh.wallX(1.05, gap / 2, 1, -1, 1);
        auto wall = mesh.collider();
        hose.setColliders({wall});
        UpdateResult r;
        bool everBlocked = false;
        for (int s = 1; s <= steps; ++s) {
            r = hose.grab(20, Vec3(1.0 + 0.15 * s / steps, 0.002, 0));
            everBlocked |= r.blocked;
            for (int i = 0; i < hose.pointCount(); ++i)
                ASSERT_LT(hose.point(i).x(), 1.05) << "step " << s;
        }
        EXPECT_TRUE(everBlocked);
        EXPECT_TRUE(r.blocked);
        EXPECT_GT(r.grabError, 0.09);
        EXPECT_GE(sampledClearance(hose, *wall), -1e-4);
    }
}

TEST(HoseCollision, HosePassesAGapWiderThanItsDiameter)
{
    Hose hose = straightHose();
    Mesh mesh;
    mesh.wallX(1.05, -1, -0.015, -1, 1);
    mesh.wallX(1.05, 0.015, 1, -1, 1);
    auto wall = mesh.collider();
    hose.setColliders({wall});
    UpdateResult r;
    for (int s = 1; s <= 10; ++s)
        r = hose.grab(20, Vec3(1.0 + 0.015 * s, 0, 0));
    EXPECT_FALSE(r.blocked);
    EXPECT_EQ(r.status, Status::Ok);
    EXPECT_LT((hose.point(20) - Vec3(1.15, 0, 0)).norm(), 1e-9);
    EXPECT_GE(sampledClearance(hose, *wall), -1e-4);
}

TEST(HoseCollision, HoseWrapsASharpEdgeWithoutCuttingTheCorner)
{
    for (const int steps : {1, 30}) {
        // Fixed at x = 0 above a block whose top edge runs along z at x = 0.5, y = 0.1.
        Hose hose = straightHose(20, 1.0, {0, 0.2, 0});
        Mesh mesh;
        mesh.box({-0.5, -1, -0.5}, {0.5, 0.1, 0.5});
        auto block = mesh.collider();
        hose.setColliders({block});
        UpdateResult r;
        const Vec3 from(1.0, 0.2, 0), to(0.8, -0.3, 0);
        for (int s = 1; s <= steps; ++s)
            r = hose.grab(20, from + (to - from) * (double(s) / steps));
        EXPECT_GE(sampledClearance(hose, *block), -1e-4) << "steps " << steps;
        const Violation v = violation(hose);
        EXPECT_LE(v.length, 1e-6) << "steps " << steps;
        EXPECT_LE(v.angle, 1e-6) << "steps " << steps;
        EXPECT_GT(r.contacts, 0);
        // It really bends round the edge: the end went below the top face.
        EXPECT_LT(hose.point(20).y(), 0.0);
    }
}

TEST(HoseCollision, AttachmentMotionPushesTheHoseAlongAnObstacle)
{
    Hose hose = straightHose();
    Mesh mesh;
    mesh.quad({0.3, 0.015, -1}, {1.5, 0.015, -1}, {1.5, 0.015, 1},
              {0.3, 0.015, 1}); // a thin shelf 5 mm above
    auto shelf = mesh.collider();
    hose.setColliders({shelf});
    UpdateResult r;
    const int attachment = hose.attachments().front().id;
    for (int s = 1; s <= 20; ++s) {
        Frame frame;
        frame.translation = Vec3(0, 0.03 * s, 0);
        r = hose.moveAttachment(attachment, frame);
        ASSERT_NE(r.status, Status::InvalidInput);
        for (int i = 0; i < hose.pointCount(); ++i) {
            if (hose.point(i).x() > 0.3 + hose.outerRadius()) {
                ASSERT_LT(hose.point(i).y(), 0.015) << "point " << i;
            }
        }
    }
    // It presses against the shelf's edge (within 1 mm) without entering it.
    EXPECT_GE(sampledClearance(hose, *shelf), -1e-4);
    EXPECT_LT(sampledClearance(hose, *shelf), 1e-3);
    const Violation v = violation(hose);
    EXPECT_LE(v.length, 1e-6);
    EXPECT_LE(v.angle, 1e-6);
}

// Steps until a step changes nothing (the hose counts as settled), at most maxSteps; checks
// after every step that no point sinks into the collider and the constraints hold.
int stepUntilSettledOutside(Hose& hose, const MeshCollider& collider, int maxSteps,
                            double* worstPenetration, Violation* worstViolation)
{
    for (int s = 0; s < maxSteps; ++s) {
        const std::uint64_t revision = hose.revision();
        const UpdateResult r = hose.step();
        EXPECT_FALSE(r.blocked) << "step " << s;
        for (int i = 0; i < hose.pointCount(); ++i) {
            const MeshCollider::Closest c = collider.closestToPoint(hose.point(i));
            *worstPenetration = std::max(*worstPenetration, hose.outerRadius() - c.distance);
        }
        const Violation v = violation(hose);
        worstViolation->length = std::max(worstViolation->length, v.length);
        worstViolation->angle = std::max(worstViolation->angle, v.angle);
        if (hose.revision() == revision) return s;
    }
    return maxSteps;
}

TEST(HoseCollision, GravityLaysTheHoseOnAFloorSettlesAndStopsWithoutPenetratingOrBouncing)
{
    // Per-frame gravity (Hose::step) with a floor 0.3 m below the fixed end: the contacts are
    // projection constraints inside the gravity rounds, so the hose comes to rest and stops.
    HoseSpec spec = paperSpec(20, 0.05, 40);
    spec.gravity.enabled = true;
    Hose hose = Hose::straight({0, 0.3, 0}, Vec3::UnitX(), 1.0, spec);
    hose.attach(0, 1, Frame::identity());
    Mesh mesh;
    mesh.quad({-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2});
    auto floor = mesh.collider();
    hose.setColliders({floor});
    for (int frame = 0; frame < 100; ++frame) {
        static_cast<void>(hose.step());
        for (int i = 0; i < hose.pointCount(); ++i)
            ASSERT_LE(hose.point(i).y(), 0.3 + 1e-9)
                << "bounced: frame " << frame << " point " << i;
    }
    double penetration = 0.0;
    Violation worst;
    const int steps = stepUntilSettledOutside(hose, *floor, 3000, &penetration, &worst);
    std::printf(
        "[ figures  ] hose on a floor: settled %d steps after the first 100, deepest %.2e m\n",
        steps, penetration);
    EXPECT_LT(steps, 3000) << "settles";
    EXPECT_LE(penetration, 1e-4);
    EXPECT_LE(worst.length, 1e-9);
    EXPECT_LE(worst.angle, 1e-9);
    EXPECT_GE(sampledClearance(hose, *floor), -1e-4);
    EXPECT_NEAR(hose.point(20).y(), hose.outerRadius(), 1e-3); // the free end lies on the floor
    int lying = 0;
    for (int i = 0; i < hose.pointCount(); ++i)
        lying += hose.point(i).y() < hose.outerRadius() + 2e-5; // 10 um skin
    EXPECT_GE(lying, 5) << "a good part of it rests on the floor";
    // Settled: nothing moves, bit for bit.
    const std::vector<Vec3> settled = hose.points();
    const std::uint64_t revision = hose.revision();
    for (int s = 0; s < 200; ++s)
        EXPECT_EQ(hose.step().movedPoints, 0);
    EXPECT_EQ(hose.points(), settled);
    EXPECT_EQ(hose.revision(), revision);
}

TEST(HoseCollision, HoseDroppedOntoABoxSettlesOutsideItAndStops)
{
    // Both ends clamped 0.1 m above the top of a generated box (12 triangles); 1.2 m of hose
    // over 0.8 m would hang 0.29 m deep: it lands on the box and rests there. Bend-limited
    // (joint projection with the contacts) and without a bend limit (same path once touching).
    for (const double radius : {0.05, 0.0}) {
        HoseSpec spec;
        spec.segmentCount = 40;
        spec.material.expansionCoefficient = 0.01;
        spec.material.bendLimit = BendLimit::minBendRadius(radius);
        spec.gravity.enabled = true;
        Hose hose = Hose::alongRoute({Vec3(-0.5, 0.1, 0), Vec3(-0.4, 0.1, 0), Vec3(0, 0.5, 0),
                                      Vec3(0.4, 0.1, 0), Vec3(0.5, 0.1, 0)},
                                     spec);
        hose.attach(0, 1, Frame::identity());
        hose.attach(39, 40, Frame::identity());
        Mesh mesh;
        mesh.box({-1, -0.5, -0.5}, {1, 0, 0.5});
        auto box = mesh.collider();
        hose.setColliders({box});
        double penetration = 0.0;
        Violation worst;
        const int steps = stepUntilSettledOutside(hose, *box, 5000, &penetration, &worst);
        double lowest = 1e300;
        for (const Vec3& p : hose.points())
            lowest = std::min(lowest, p.y());
        std::printf("[ figures  ] hose dropped onto a box (R %.2f m): settled after %d steps, "
                    "lowest axis point "
                    "%.6f m, deepest %.2e m\n",
                    radius, steps, lowest, penetration);
        EXPECT_LT(steps, 5000) << "settles, R " << radius;
        EXPECT_LE(penetration, 1e-4) << radius;
        EXPECT_GE(sampledClearance(hose, *box), -1e-4) << radius;
        EXPECT_NEAR(lowest, hose.outerRadius(), 1e-4) << "it rests on the top face, R " << radius;
        EXPECT_LE(worst.length, 1e-9) << radius;
        EXPECT_LE(worst.angle, 1e-9) << radius;
        const std::vector<Vec3> settled = hose.points();
        for (int s = 0; s < 200; ++s)
            EXPECT_EQ(hose.step().movedPoints, 0) << radius;
        EXPECT_EQ(hose.points(), settled) << radius;
    }
}

TEST(HoseCollision, MovedColliderPushesTheHoseOutOnResolve)
{
    Hose hose = straightHose();
    Mesh mesh;
    mesh.box({0.4, -0.5, -0.5}, {0.6, -0.02, 0.5});
    auto block = mesh.collider();
    hose.setColliders({block});
    EXPECT_GT(sampledClearance(hose, *block), 0.0);
    Frame up;
    up.translation = Vec3(0, 0.025, 0); // the block's top now cuts 15 mm into the hose
    ASSERT_TRUE(block->setFrame(up));
    const UpdateResult r = hose.resolveCollisions();
    EXPECT_FALSE(r.blocked);
    EXPECT_GE(sampledClearance(hose, *block), -1e-4);
    EXPECT_GT(hose.point(10).y(), 0.005 + hose.outerRadius() - 1e-4);
}

TEST(HoseCollision, AFloorRaisedUnderATautHoseIsRefusedAndTheHoseKeepsItsShape)
{
    // An inextensible hose fixed straight at both ends 1 mm above a floor; the floor rises 5 mm
    // (half the hose's radius: a collider moving farther in one update can pass through a hose).
    // No shape between the fixed ends clears it (the hose has no slack to rise): the
    // contacts' projection finds none, no fixed point moved, so the update is refused at once
    // (no contact rounds): the hose keeps its last collision-resolved shape, every constraint
    // as it was, reported blocked and, still inside the floor, Infeasible.
    HoseSpec spec = paperSpec(20, 0.0, 40);
    const double radius = 0.5 * spec.outerDiameter;
    Hose hose = Hose::straight({0, radius + 0.001, 0}, Vec3::UnitX(), 1.0, spec);
    hose.attach(0, 1, Frame::identity());
    hose.attach(19, 20, Frame::identity());
    Mesh mesh;
    mesh.quad({-1, 0, -1}, {-1, 0, 1}, {2, 0, 1}, {2, 0, -1});
    auto floor = mesh.collider();
    hose.setColliders({floor});
    const std::vector<Vec3> before = hose.points();
    Frame up;
    up.translation = Vec3(0, 0.005, 0);
    ASSERT_TRUE(floor->setFrame(up));
    const UpdateResult r = hose.resolveCollisions();
    EXPECT_TRUE(r.blocked);
    EXPECT_EQ(r.status, Status::Infeasible);
    EXPECT_NEAR(r.penetration, 0.004, 1e-9) << "radius − (1 mm + 10 mm − 5 mm)";
    EXPECT_EQ(hose.points(), before);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    EXPECT_LE(r.iterations, 8 + 2 * 32) << "the projection's steps and its closing, no more";
}

TEST(HoseCollision, AttachmentDrivenIntoAnObjectIsReportedBlocked)
{
    Hose hose = straightHose();
    Mesh mesh;
    mesh.box({-0.5, 0.2, -0.5}, {0.5, 0.6, 0.5});
    auto block = mesh.collider();
    hose.setColliders({block});
    Frame frame;
    frame.translation = Vec3(0, 0.3, 0); // the fixed points end up 0.1 m inside the block
    const UpdateResult r = hose.moveAttachment(hose.attachments().front().id, frame);
    EXPECT_TRUE(r.blocked);
    // Surfaces only: the depth is the radius minus the axis's distance to the crossed face.
    EXPECT_GT(r.penetration, 0.5 * hose.outerRadius());
    EXPECT_LE(r.penetration, hose.outerRadius());
    for (int i = 0; i < hose.pointCount(); ++i)
        EXPECT_TRUE(hose.point(i).allFinite());
}

TEST(HoseCollision, SetCollidersRefusesBadOptions)
{
    Hose hose = straightHose();
    EXPECT_THROW(hose.setColliders({nullptr}), InvalidArgument);
    CollisionOptions options;
    options.tolerance = 0.0;
    Mesh mesh;
    mesh.wallX(1, -1, 1, -1, 1);
    EXPECT_THROW(hose.setColliders({mesh.collider()}, options), InvalidArgument);
    options = CollisionOptions();
    options.maxRounds = 0;
    EXPECT_THROW(hose.setColliders({mesh.collider()}, options), InvalidArgument);
}

TEST(HoseCollision, MillionTriangleSceneStaysInteractive)
{
    // A 708 × 708 height field of 1,002,528 triangles, 2 m square, with bumps; the hose is
    // dragged over it. Figures are printed for the performance notes, never asserted.
    const int cells = 708;
    Mesh mesh;
    mesh.positions.reserve(static_cast<size_t>((cells + 1) * (cells + 1)));
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i) {
            const double x = -1.0 + 2.0 * i / cells, z = -1.0 + 2.0 * j / cells;
            mesh.positions.emplace_back(x, 0.02 * std::sin(9 * x) * std::cos(7 * z), z);
        }
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const auto v = static_cast<std::uint32_t>(j * (cells + 1) + i), w = v + cells + 1;
            mesh.indices.insert(mesh.indices.end(), {v, v + 1, w + 1, v, w + 1, w});
        }
    const auto t0 = std::chrono::steady_clock::now();
    auto ground = mesh.collider();
    const auto t1 = std::chrono::steady_clock::now();
    EXPECT_EQ(ground->triangleCount(), 2 * cells * cells);
    Hose hose = straightHose(50, 1.0, {-0.5, 0.1, 0});
    hose.setColliders({ground});
    const int updates = 200;
    double worst = 0.0;
    for (int s = 1; s <= updates; ++s) {
        const double a = 0.05 * s;
        const auto u0 = std::chrono::steady_clock::now();
        static_cast<void>(hose.grab(
            50, Vec3(-0.5 + std::cos(a) * 0.8, -0.05, std::sin(a) * 0.8))); // below the ground
        worst = std::max(
            worst, std::chrono::duration<double>(std::chrono::steady_clock::now() - u0).count());
    }
    const auto t2 = std::chrono::steady_clock::now();
    EXPECT_GE(sampledClearance(hose, *ground), -1e-4);
    std::printf("[ figures  ] 1M triangles: build %.2f s, %.3f ms per grab (50-segment hose on the "
                "ground), worst %.3f ms\n",
                std::chrono::duration<double>(t1 - t0).count(),
                1e3 * std::chrono::duration<double>(t2 - t1).count() / updates, 1e3 * worst);
}

// --- clearance
// ------------------------------------------------------------------------------------

TEST(Clearance, MinimumDistanceAndWhereItOccurs)
{
    Hose hose = straightHose(20, 1.0, {0, 0, 0});
    // A cube standing on an edge: its lowest edge runs along z, 30 mm above the axis at x = 0.66.
    Mesh mesh;
    mesh.box({-0.04, -0.04, -0.1}, {0.04, 0.04, 0.1});
    Frame place;
    place.rotation = Quat(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
    place.translation = Vec3(0.66, 0.03 + 0.04 * std::sqrt(2.0), 0);
    auto block = mesh.collider(place);
    const Clearance c = clearance(hose, *block);
    ASSERT_TRUE(c.found);
    EXPECT_NEAR(c.distance, 0.03 - hose.outerRadius(), 1e-12);
    EXPECT_LT((c.onObject - Vec3(0.66, 0.03, c.onObject.z())).norm(), 1e-12);
    EXPECT_LT((c.onAxis - Vec3(0.66, 0, 0)).norm(), 1e-12);
    EXPECT_LT((c.onSurface - Vec3(0.66, hose.outerRadius(), 0)).norm(), 1e-12);
    EXPECT_EQ(c.segment, 13);
    EXPECT_EQ(c.axisPoint, 13); // 0.66 lies nearer to point 13 (0.65) than to 14 (0.70)
    EXPECT_NEAR(c.distance, sampledClearance(hose, *block), 1e-5); // 1 mm sampling
    // Invariant under a rigid motion of both.
    Frame motion;
    motion.rotation = Quat(Eigen::AngleAxisd(1.1, Vec3(0, 1, 1).normalized()));
    motion.translation = Vec3(3, 4, 5);
    std::vector<Vec3> axis;
    for (const Vec3& p : hose.points())
        axis.push_back(motion.apply(p));
    const Hose moved = Hose::fromAxis(axis, hose.spec());
    block->setFrame(motion * place);
    const Clearance cm = clearance(moved, *block);
    EXPECT_NEAR(cm.distance, c.distance, 1e-12);
    EXPECT_EQ(cm.axisPoint, c.axisPoint);
    // Beyond the search distance: not found.
    EXPECT_FALSE(clearance(moved, *block, 0.005).found);
    // Inside: negative.
    Mesh inside;
    inside.box({0.4, -0.005, -0.1}, {0.5, 0.1, 0.1});
    EXPECT_NEAR(clearance(hose, *inside.collider()).distance, -hose.outerRadius(), 1e-12);
}

} // namespace
} // namespace chaintube::test
