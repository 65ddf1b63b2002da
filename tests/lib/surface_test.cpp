#include "test_util.h"

using namespace chaintube;
using namespace chaintube::test;

namespace {
Hose wiggly(int segments = 30)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(segments, 0.1, 40));
    static_cast<void>(hose.grab(segments / 3, Vec3(0.3, 0.2, 0.1)));
    static_cast<void>(hose.grab(2 * segments / 3, Vec3(0.6, -0.1, 0.3)));
    return hose;
}

void expectOrthonormal(const RingFrame& r, double tolerance)
{
    EXPECT_NEAR(r.tangent.norm(), 1.0, tolerance);
    EXPECT_NEAR(r.alignment.norm(), 1.0, tolerance);
    EXPECT_NEAR(r.tangent.dot(r.alignment), 0.0, tolerance);
    EXPECT_LT((r.binormal - r.tangent.cross(r.alignment)).norm(), tolerance);
}
} // namespace

TEST(Surface, RingsLieOnTheBisectorPlaneOfTheirSegments)
{
    const Hose hose = wiggly();
    TwistSeed seed;
    std::vector<RingFrame> frames;
    computeRingFrames(hose, seed, frames);
    const auto& p = hose.localPoints();
    for (size_t i = 1; i + 1 < frames.size(); ++i) {
        const Vec3 in = (p[i] - p[i - 1]).normalized(), out = (p[i + 1] - p[i]).normalized();
        EXPECT_NEAR(frames[i].tangent.dot(in), frames[i].tangent.dot(out), 1e-12) << i;
        // To rounding, whichever normalisation the machine uses (the AVX-512 path refines an
        // approximate reciprocal square root: one refinement too few shows here as ~1e-8).
        EXPECT_LT((frames[i].tangent - (in + out).normalized()).norm(), 2e-15) << i;
        expectOrthonormal(frames[i], 1e-12);
    }
    EXPECT_LT((frames.front().tangent - (p[1] - p[0]).normalized()).norm(), 1e-12);
}

TEST(Surface, StraightHoseHasCollinearRingsWithoutTwist)
{
    const Hose hose = Hose::straight(Vec3(1, 2, 3), Vec3(1, 1, 0), 1.0, paperSpec(50));
    TwistSeed seed;
    std::vector<RingFrame> frames;
    computeRingFrames(hose, seed, frames);
    for (const RingFrame& r : frames) {
        EXPECT_LT((r.tangent - frames[0].tangent).norm(), 1e-12);
        EXPECT_LT((r.alignment - frames[0].alignment).norm(), 1e-12);
    }
}

TEST(Surface, TwistCorrectionAgreesWithThePapersAlignmentProjectionForGentleBends)
{
    const Hose hose = wiggly(120);
    TwistSeed seed;
    std::vector<RingFrame> frames;
    computeRingFrames(hose, seed, frames);
    for (size_t i = 1; i < frames.size(); ++i) {
        // Paper: project the previous alignment onto this ring plane.
        const Vec3 projected = (frames[i - 1].alignment -
                                frames[i - 1].alignment.dot(frames[i].tangent) * frames[i].tangent)
                                   .normalized();
        EXPECT_GT(projected.dot(frames[i].alignment), 0.995) << i;
    }
}

// The chain takes two rings a step where both projections are well conditioned (the second
// projection's dot product rewritten as b − a·c) and single steps elsewhere: either way every
// ring's alignment is the paper's projection of the previous ring's, to rounding. Odd and even
// ring counts (a single step left at the end or not), and a hose with right-angle corners
// (where the chain falls back to the double reflection, then resumes pairs at an odd ring).
TEST(Surface, TwoRingStepsGiveThePapersProjectionToRounding)
{
    std::vector<Hose> hoses = {wiggly(120), wiggly(121)};
    HoseSpec spec = paperSpec(6, 0.1, 100);
    hoses.push_back(
        Hose::fromAxis({Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.2, 0, 0), Vec3(0.2, 0.1, 0),
                        Vec3(0.2, 0.2, 0.01), Vec3(0.2, 0.2, 0.11), Vec3(0.3, 0.21, 0.12)},
                       spec));
    for (const Hose& hose : hoses) {
        TwistSeed seed;
        std::vector<RingFrame> frames;
        computeRingFrames(hose, seed, frames);
        int projections = 0;
        for (size_t i = 1; i < frames.size(); ++i) {
            expectOrthonormal(frames[i], 1e-14);
            const Vec3 raw = frames[i - 1].alignment -
                             frames[i - 1].alignment.dot(frames[i].tangent) * frames[i].tangent;
            if (raw.squaredNorm() <= 1e-3) continue; // the double reflection's territory
            ++projections;
            EXPECT_LT((raw.normalized() - frames[i].alignment).norm(), 1e-13)
                << "ring " << i << " of " << frames.size();
        }
        EXPECT_GE(projections, static_cast<int>(frames.size()) / 2);
    }
}

TEST(Surface, FoldBackAndZigZagAxesStillGiveOrthonormalFrames)
{
    HoseSpec spec = paperSpec(4, 0.1, 179);
    const std::vector<Vec3> axis = {Vec3(0, 0, 0), Vec3(1, 0, 0),
                                    Vec3(0, 0, 0.0) + Vec3(0, 1e-13, 0), Vec3(1, 0, 1e-13),
                                    Vec3(1, 1, 0)};
    const Hose hose = Hose::fromAxis(axis, spec);
    TwistSeed seed;
    std::vector<RingFrame> frames;
    computeRingFrames(hose, seed, frames);
    for (const RingFrame& r : frames) {
        EXPECT_TRUE(r.tangent.allFinite() && r.alignment.allFinite() && r.binormal.allFinite());
        expectOrthonormal(r, 1e-9);
    }
}

TEST(Surface, VerticesAreOnTheRingsAndTrianglesFaceOutwards)
{
    const Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitZ(), 1.0, paperSpec(10));
    const HoseSurface surface(hose);
    const SurfaceTopology& t = surface.topology();
    EXPECT_EQ(t.ringVertexCount, 17);
    EXPECT_EQ(t.vertexCount, 11 * 17 + 2 * 16);
    EXPECT_EQ(t.indices.size(), 3u * (10 * 16 * 2 + 2 * 14));
    const std::span<const float> pos = surface.positions();
    const std::span<const float> nrm = surface.normals();
    for (int v = 0; v < 11 * 17; ++v) {
        const Vec3 p(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);
        EXPECT_NEAR(std::hypot(p.x(), p.y()), 0.01, 1e-7);
        EXPECT_NEAR(p.z(), 0.1 * (v / 17), 1e-7);
        EXPECT_NEAR(Vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]).norm(), 1.0, 1e-6);
        EXPECT_FLOAT_EQ(t.uvs[2 * v + 1], static_cast<float>(0.1 * (v / 17)));
    }
    for (size_t k = 0; k < t.indices.size(); k += 3) {
        Vec3 c[3];
        for (int m = 0; m < 3; ++m) {
            ASSERT_LT(t.indices[k + m], static_cast<std::uint32_t>(t.vertexCount));
            const std::uint32_t v = t.indices[k + m];
            c[m] = Vec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);
        }
        const Vec3 normal = (c[1] - c[0]).cross(c[2] - c[0]);
        const Vec3 centroid = (c[0] + c[1] + c[2]) / 3.0;
        Vec3 outward(centroid.x(), centroid.y(), 0.0);
        if (centroid.z() < 1e-6)
            outward = -Vec3::UnitZ(); // start cap
        else if (centroid.z() > 1.0 - 1e-6)
            outward = Vec3::UnitZ(); // end cap
        EXPECT_GT(normal.dot(outward), 0.0) << "triangle " << k / 3;
    }
}

TEST(Surface, FirstRingDoesNotPopBetweenFrames)
{
    Hose hose = wiggly();
    HoseSurface surface(hose);
    Vec3 previous = surface.frames()[0].alignment;
    for (int step = 0; step < 100; ++step) {
        static_cast<void>(hose.grab(0, hose.point(0) + Vec3(0.0, 0.005, 0.003)));
        surface.update(hose);
        const Vec3 now = surface.frames()[0].alignment;
        EXPECT_GT(now.dot(previous), 0.99) << step;
        previous = now;
    }
}

TEST(Surface, EveryProfileShapeGivesFiniteUnitNormals)
{
    const std::vector<Profile> profiles = {
        Profile::circle(0.01, 3), Profile::ellipse(0.02, 0.005, 12), Profile::rectangle(0.02, 0.01),
        Profile::roundedRectangle(0.03, 0.01, 0.004, 3),
        Profile::polygon(
            {Vec2(0, 0), Vec2(0.01, 0), Vec2(0.01, 0.01), Vec2(0.005, 0.004), Vec2(0, 0.01)}, 0.3)};
    for (const Profile& profile : profiles) {
        HoseSpec spec = paperSpec(8);
        spec.profile = profile;
        Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.5, spec);
        static_cast<void>(hose.grab(4, Vec3(0.2, 0.1, 0.0)));
        const HoseSurface surface(hose);
        for (size_t k = 0; k < surface.normals().size(); k += 3) {
            const Vec3 n(surface.normals()[k], surface.normals()[k + 1], surface.normals()[k + 2]);
            EXPECT_NEAR(n.norm(), 1.0, 1e-6);
        }
        for (float x : surface.positions())
            EXPECT_TRUE(std::isfinite(x));
    }
}

// The vectorised ring writer (blocks of 8 floats in the xyz phase patterns, unrolled by three,
// a ring's last block spilling into the next ring): every ring vertex and normal is its profile
// point placed by the ring's frame, for side counts that give every block and tail layout.
TEST(Surface, EveryRingVertexIsItsProfilePointInTheRingFrameForEverySideCount)
{
    for (int sides : {3, 5, 8, 12, 16, 24, 32, 48}) {
        for (int segments : {29, 30}) {
            HoseSpec spec = paperSpec(segments, 0.1, 40);
            spec.profile = Profile::circle(0.01, sides);
            Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
            static_cast<void>(hose.grab(segments / 3, Vec3(0.3, 0.2, 0.1)));
            static_cast<void>(hose.grab(2 * segments / 3, Vec3(0.6, -0.1, 0.3)));
            const HoseSurface surface(hose);
            const Profile& profile = hose.profile();
            const int ringVertices = surface.topology().ringVertexCount;
            ASSERT_EQ(ringVertices, static_cast<int>(profile.points().size()));
            const std::span<const float> pos = surface.positions();
            const std::span<const float> nrm = surface.normals();
            double worstPosition = 0.0, worstNormal = 0.0;
            for (int i = 0; i < hose.pointCount(); ++i) {
                const RingFrame& ring = surface.frames()[static_cast<size_t>(i)];
                for (int j = 0; j < ringVertices; ++j) {
                    const Vec2& q = profile.points()[static_cast<size_t>(j)];
                    const Vec2& m = profile.normals()[static_cast<size_t>(j)];
                    const Vec3 expected =
                        ring.center + q.x() * ring.alignment + q.y() * ring.binormal;
                    const Vec3 expectedNormal = m.x() * ring.alignment + m.y() * ring.binormal;
                    const size_t v = 3 * static_cast<size_t>(i * ringVertices + j);
                    worstPosition = std::max(
                        worstPosition, (Vec3(pos[v], pos[v + 1], pos[v + 2]) - expected).norm());
                    worstNormal =
                        std::max(worstNormal,
                                 (Vec3(nrm[v], nrm[v + 1], nrm[v + 2]) - expectedNormal).norm());
                }
            }
            EXPECT_LT(worstPosition, 1e-6) << sides << " sides, " << segments << " segments";
            EXPECT_LT(worstNormal, 1e-6) << sides << " sides, " << segments << " segments";
        }
    }
}
