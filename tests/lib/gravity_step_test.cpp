// Per-frame gravity (HoseSpec::gravity, Hose::step): settles like sag(), holds the constraints
// after every step, never jitters once settled, costs nothing when off or settled.
#include "test_util.h"

using namespace chaintube;
using namespace chaintube::test;

namespace {
// Inextensible, no bend limit, hung from two points 1 m apart (the catenary set-up of sag_test).
Hose hangingHose(double length, int segments)
{
    HoseSpec spec;
    spec.segmentCount = segments;
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.0);
    spec.gravity.enabled = true;
    const double half = 0.5 * length, depth = std::sqrt(half * half - 0.25);
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.5, -depth, 0.0), Vec3(1, 0, 0)}, spec);
    hose.attach(0, 0, Frame::identity());
    hose.attach(segments, segments, Frame::identity());
    return hose;
}

double lowestY(const Hose& hose)
{
    double lowest = 1e300;
    for (const Vec3& p : hose.points()) lowest = std::min(lowest, p.y());
    return lowest;
}

// Steps until settled (a step that does nothing), at most maxSteps. Returns the steps taken.
int stepUntilSettled(Hose& hose, int maxSteps, double* worstLength = nullptr, double* worstAngle = nullptr)
{
    for (int s = 0; s < maxSteps; ++s) {
        const std::uint64_t revision = hose.revision();
        const UpdateResult r = hose.step();
        if (worstLength) *worstLength = std::max(*worstLength, r.lengthViolation);
        if (worstAngle) *worstAngle = std::max(*worstAngle, r.angleViolation);
        if (hose.revision() == revision) return s;
    }
    return maxSteps;
}
} // namespace

TEST(GravityStep, OffCostsNothingAndChangesNothing)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec());
    hose.attach(0, 0, Frame::identity());
    const std::uint64_t revision = hose.revision();
    const std::vector<Vec3> before = hose.points();
    const UpdateResult r = hose.step();
    EXPECT_EQ(r.status, Status::Ok);
    EXPECT_EQ(r.movedPoints, 0);
    EXPECT_EQ(hose.revision(), revision);
    EXPECT_EQ(hose.points(), before);
}

TEST(GravityStep, SettlesToTheCatenaryWithEveryConstraintHoldingAfterEveryStep)
{
    const std::pair<double, double> cases[] = {{1.05, 0.13930}, {1.2, 0.29234}, {2.0, 0.79639}};
    for (const auto& [length, expected] : cases) {
        Hose hose = hangingHose(length, 64);
        double worstLength = 0.0, worstAngle = 0.0;
        const int steps = stepUntilSettled(hose, 20000, &worstLength, &worstAngle);
        EXPECT_LT(steps, 20000) << "length " << length << " did not settle";
        EXPECT_NEAR(-lowestY(hose), expected, 0.01 * expected) << "length " << length << " after " << steps << " steps";
        EXPECT_LE(worstLength, 1e-9) << "length " << length;
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    }
}

TEST(GravityStep, SettledHoseNeverJitters)
{
    Hose hose = hangingHose(1.2, 32);
    ASSERT_LT(stepUntilSettled(hose, 20000), 20000);
    const std::vector<Vec3> settled = hose.points();
    const std::uint64_t revision = hose.revision();
    for (int s = 0; s < 500; ++s) {
        const UpdateResult r = hose.step();
        EXPECT_EQ(r.movedPoints, 0);
    }
    EXPECT_EQ(hose.points(), settled) << "bit for bit";
    EXPECT_EQ(hose.revision(), revision) << "surfaces are not recomputed";
}

TEST(GravityStep, IsDeterministic)
{
    Hose a = hangingHose(1.2, 40), b = hangingHose(1.2, 40);
    for (int s = 0; s < 300; ++s) {
        a.step();
        b.step();
        if (s == 100) {
            a.grab(20, Vec3(0.5, 0.1, 0.2));
            b.grab(20, Vec3(0.5, 0.1, 0.2));
        }
    }
    EXPECT_EQ(a.points(), b.points());
}

TEST(GravityStep, HeldPointStaysWhileTheRestHangsAndFallsWhenReleased)
{
    HoseSpec spec = paperSpec();
    spec.segmentCount = 30;
    spec.material.bendLimit = BendLimit::minBendRadius(0.05);
    spec.gravity.enabled = true;
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.5, spec);
    hose.attach(0, 1, Frame::identity());
    const Vec3 target(0.9, 0.3, 0.0);
    hose.grab(30, target);
    EXPECT_EQ(hose.heldPoint(), 30);
    double worstLength = 0.0, worstAngle = 0.0;
    stepUntilSettled(hose, 5000, &worstLength, &worstAngle);
    EXPECT_LT((hose.point(30) - target).norm(), 1e-12) << "the held end stays at its grab target";
    EXPECT_LT(hose.point(15).y(), -0.05) << "the middle sags between the clamp and the hand";
    EXPECT_LE(worstLength, 1e-9);
    EXPECT_LE(worstAngle, 1e-9);
    hose.releaseGrab();
    EXPECT_EQ(hose.heldPoint(), -1);
    stepUntilSettled(hose, 5000);
    EXPECT_LT(hose.point(30).y(), -0.3) << "released, the end falls and hangs from the clamp";
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}

TEST(GravityStep, DraggingDoesNotFlingTheHose)
{
    // The displacement of a grab carries no velocity: right after a large jump of the held
    // point, one step moves the far part of the hose by about one gravity round, no more.
    Hose hose = hangingHose(1.2, 40);
    ASSERT_LT(stepUntilSettled(hose, 20000), 20000);
    hose.detach(hose.attachments().back().id);
    hose.grab(40, Vec3(1.0, 0.5, 0.0));
    stepUntilSettled(hose, 20000);
    hose.grab(40, Vec3(1.3, 0.5, 0.3));
    const std::vector<Vec3> afterGrab = hose.points();
    hose.step(1);
    const double mean = hose.restLengthTotal() / 40;
    EXPECT_LT((hose.point(5) - afterGrab[5]).norm(), 0.2 * mean);
}

TEST(GravityStep, NothingToHangFromDoesNotFall)
{
    HoseSpec spec = paperSpec();
    spec.gravity.enabled = true;
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    const std::vector<Vec3> before = hose.points();
    EXPECT_EQ(hose.step().status, Status::Ok);
    EXPECT_EQ(hose.points(), before);
}

TEST(GravityStep, SceneStepsOnlyHosesThatNeedIt)
{
    Scene scene;
    Hose still = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec());
    still.attach(0, 0, Frame::identity());
    scene.addHose(still);
    scene.addHose(hangingHose(1.2, 32));
    EXPECT_EQ(scene.step(), 1) << "only the hose with gravity on moves";
    for (int s = 0; s < 20000 && scene.step() > 0;) ++s;
    EXPECT_EQ(scene.step(), 0) << "settled";
}
