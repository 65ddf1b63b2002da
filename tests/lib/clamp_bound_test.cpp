// A grab between two fixed segments pulled out of reach: bounded by the stretch balls of both
// sides, the clamp stops inside them, on the line towards the target, with every constraint.
#include "test_util.h"

using namespace chaintube;
using namespace chaintube::test;

TEST(ClampBetweenFixedPoints, StopsOnTheLineInsideBothStretchBallsWithEveryConstraint)
{
    HoseSpec spec;
    spec.segmentLength = 0.02;
    spec.material.expansionCoefficient = 0.05;
    spec.material.bendLimit = BendLimit::minBendRadius(0.06);
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.5, 0.3, 0), Vec3(1, 0, 0)}, spec);
    const int n = hose.pointCount(), k = n / 2;
    hose.attach(0, 1, Frame::identity());
    hose.attach(n - 2, n - 1, Frame::identity());
    double reachLeft = 0.0, reachRight = 0.0;
    for (int s = 1; s < k; ++s) reachLeft += hose.maxLength(s);
    for (int s = k; s < n - 2; ++s) reachRight += hose.maxLength(s);
    for (int trial = 0; trial < 12; ++trial) {
        const double phase = 0.5 * trial;
        const Vec3 start = hose.point(k);
        const Vec3 target(0.5 + 1.5 * std::cos(phase), 0.3 + 1.5 * std::sin(phase), 0.3 * std::sin(2 * phase));
        const UpdateResult r = hose.grab(k, target);
        ASSERT_EQ(r.status, Status::Clamped) << "trial " << trial;
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
        const Vec3 p = hose.point(k);
        EXPECT_LE((p - hose.point(1)).norm(), reachLeft * (1 + 1e-9));
        EXPECT_LE((p - hose.point(n - 2)).norm(), reachRight * (1 + 1e-9));
        // On the segment from where it was towards the target.
        const Vec3 move = target - start;
        const double t = (p - start).dot(move) / move.squaredNorm();
        EXPECT_GE(t, 0.0);
        EXPECT_LT(t, 1.0);
        EXPECT_LT((start + t * move - p).norm(), 1e-9);
        EXPECT_NEAR(r.grabError, (p - target).norm(), 1e-12);
    }
}

TEST(ClampBetweenFixedPoints, IsDeterministic)
{
    HoseSpec spec = paperSpec(30);
    Hose a = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    a.attach(0, 1, Frame::identity());
    a.attach(29, 30, Frame::identity());
    Hose b = a;
    for (int trial = 0; trial < 5; ++trial) {
        const Vec3 target(0.5, 2.0 + trial, 0.5 * trial);
        static_cast<void>(a.grab(15, target));
        static_cast<void>(b.grab(15, target));
    }
    EXPECT_EQ(a.points(), b.points());
}

// Held beyond reach (the same target again, as a hand held still does): the point is already
// as far as the line towards the target allows, so the hose stays exactly as it is.
TEST(ClampBetweenFixedPoints, HoldingATargetBeyondReachLeavesTheHoseAsItIs)
{
    HoseSpec spec = paperSpec(40);
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    const int n = hose.pointCount(), k = n / 2;
    hose.attach(0, 0, Frame::identity());
    const int end = hose.attach(n - 1, n - 1, Frame::identity());
    Frame closer;
    closer.translation = Vec3(-0.2, 0.0, 0.0);
    ASSERT_EQ(hose.moveAttachment(end, closer).status, Status::Ok);
    const Vec3 target(0.4, 0.6, 0.0); // the apex of the taut span is below 0.5
    const UpdateResult pulled = hose.grab(k, target);
    ASSERT_EQ(pulled.status, Status::Clamped);
    const std::vector<Vec3> atTheEdge = hose.points();
    for (int frame = 0; frame < 3; ++frame) {
        const UpdateResult held = hose.grab(k, target);
        EXPECT_EQ(held.status, Status::Clamped);
        EXPECT_EQ(hose.points(), atTheEdge) << "frame " << frame;
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    }
}

// The same target again with nothing changed: the grab returns the same answer without any
// work (no points moved, revision unchanged, so the surface is not rebuilt either). A moved
// target, a release in between, or colliders (which move without the hose knowing) do the
// work again.
TEST(ClampBetweenFixedPoints, ARepeatedGrabBeyondReachDoesNoWorkAndKeepsTheRevision)
{
    HoseSpec spec = paperSpec(40, 0.0);
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    auto pulledHose = [&]() {
        Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
        hose.attach(0, 0, Frame::identity());
        const int end = hose.attach(hose.pointCount() - 1, hose.pointCount() - 1, Frame::identity());
        Frame closer;
        closer.translation = Vec3(-0.2, 0.0, 0.0);
        EXPECT_EQ(hose.moveAttachment(end, closer).status, Status::Ok);
        return hose;
    };
    const Vec3 target(0.4, 0.6, 0.0);
    Hose hose = pulledHose();
    const int k = hose.pointCount() / 2;
    const UpdateResult pulled = hose.grab(k, target);
    ASSERT_EQ(pulled.status, Status::Clamped);
    const std::vector<Vec3> atTheEdge = hose.points();
    const std::uint64_t revision = hose.revision();
    const UpdateResult held = hose.grab(k, target);
    EXPECT_EQ(held.status, Status::Clamped);
    EXPECT_EQ(held.movedPoints, 0);
    EXPECT_EQ(held.grabError, pulled.grabError);
    EXPECT_EQ(held.lengthViolation, pulled.lengthViolation);
    EXPECT_EQ(held.angleViolation, pulled.angleViolation);
    EXPECT_EQ(hose.revision(), revision);
    EXPECT_EQ(hose.points(), atTheEdge);

    static_cast<void>(hose.grab(k, target + Vec3(0.0, 1e-9, 0.0)));
    EXPECT_GT(hose.revision(), revision) << "a moved target is a new request";
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);

    Hose released = pulledHose();
    static_cast<void>(released.grab(k, target));
    released.releaseGrab();
    const std::uint64_t beforeRegrab = released.revision();
    EXPECT_EQ(released.grab(k, target).status, Status::Clamped);
    EXPECT_GT(released.revision(), beforeRegrab) << "a grab after a release is a new request";

    Hose withColliders = pulledHose();
    const std::vector<Vec3> far = {Vec3(10, 10, 10), Vec3(11, 10, 10), Vec3(10, 11, 10)};
    withColliders.setColliders({MeshCollider::fromArrays(far, {0, 1, 2}, Frame::identity())});
    static_cast<void>(withColliders.grab(k, target));
    const std::uint64_t beforeRepeat = withColliders.revision();
    EXPECT_EQ(withColliders.grab(k, target).status, Status::Clamped);
    EXPECT_GT(withColliders.revision(), beforeRepeat) << "colliders may have moved: the grab is done again";
}
