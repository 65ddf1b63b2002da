// Hard cases of the axis solver, each decided and documented in hose.h.
#include "test_util.h"

#include <limits>
#include <numbers>

using namespace chaintube;
using namespace chaintube::test;

TEST(SolverHardCases, StraightHoseDraggedAlongItsAxisStaysStraight)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(20, 0.1, 30));
    hose.attach(0, 0, Frame::identity());
    ASSERT_EQ(hose.grab(20, Vec3(2.0, 0.0, 0.0)).status, Status::Clamped); // beyond 1.1 m
    for (const Vec3& p : hose.points()) {
        EXPECT_EQ(p.y(), 0.0);
        EXPECT_EQ(p.z(), 0.0);
    }
    EXPECT_NEAR(hose.point(20).x(), 1.1, 1e-5) << "pulled to the full stretch";
}

TEST(SolverHardCases, FoldBackRequestOf180DegreesIsDecidedAndStaysWithinLimits)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(10, 0.1, 60));
    const std::vector<Vec3> p = hose.points();
    // Ask the end to fold exactly back onto the axis.
    const UpdateResult result = hose.grab(10, p[9] - (p[10] - p[9]));
    EXPECT_EQ(result.status, Status::Ok);
    EXPECT_TRUE(allFinite(hose));
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    // Deterministic: the same request gives the same answer.
    Hose again = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(10, 0.1, 60));
    static_cast<void>(again.grab(10, p[9] - (p[10] - p[9])));
    for (int i = 0; i < hose.pointCount(); ++i)
        EXPECT_EQ(hose.point(i), again.point(i));
}

TEST(SolverHardCases, DragOntoANeighbourKeepsTheSegmentDirectionAtMinimumLength)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(10, 0.2, 40));
    const Vec3 neighbour = hose.point(6);
    const UpdateResult result = hose.grab(5, neighbour); // zero-length segment requested
    EXPECT_EQ(result.status, Status::Ok);
    EXPECT_TRUE(allFinite(hose));
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    EXPECT_LT((hose.point(5) - neighbour).norm(), 1e-15);
    // Neighbour 6 kept its old direction from 5 (+x) at the minimum length 0.08.
    EXPECT_NEAR((hose.point(6) - hose.point(5)).x(), 0.08, 1e-12);
}

TEST(SolverHardCases, NanAndInfTargetsAreRejectedAndLeaveTheHoseUnchanged)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec());
    const std::vector<Vec3> before = hose.points();
    const std::uint64_t revision = hose.revision();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const Vec3& target : {Vec3(nan, 0, 0), Vec3(0, inf, 0), Vec3(0, 0, -inf)})
        EXPECT_EQ(hose.grab(3, target).status, Status::InvalidInput);
    EXPECT_EQ(hose.grab(-1, Vec3::Zero()).status, Status::InvalidInput);
    EXPECT_EQ(hose.grab(13, Vec3::Zero()).status, Status::InvalidInput);
    Frame bad;
    bad.translation = Vec3(nan, 0, 0);
    const int id = hose.attach(0, 0, Frame::identity());
    EXPECT_EQ(hose.moveAttachment(id, bad).status, Status::InvalidInput);
    EXPECT_EQ(hose.moveAttachment(id + 100, Frame::identity()).status, Status::InvalidInput);
    EXPECT_EQ(hose.grab(0, Vec3(1, 1, 1)).status, Status::InvalidInput) << "point 0 is fixed";
    EXPECT_EQ(hose.points(), before);
    EXPECT_EQ(hose.revision(), revision);
}

// The moved attachment beyond the hose's reach (lib/README.md, "Pinned spans, reach and
// gravity"): every segment stays in its band, the hose goes taut along the line between the
// fixed points, and the moved attachment is not met: it stops where the hose reaches, on the
// line from where it was towards its frame, and the gap is reported.
TEST(SolverHardCases,
     BothEndsFixedAndPulledApartBeyondReachGoesTautAndLeavesTheMovedAttachmentShort)
{
    auto run = [] {
        Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(20, 0.1, 30));
        hose.attach(0, 1, Frame::identity());
        const int far = hose.attach(19, 20, Frame::identity());
        Frame pulled;
        pulled.translation = Vec3(0.5, 0.0, 0.0); // ends now 1.5 m apart, max length 1.1 m
        const UpdateResult result = hose.moveAttachment(far, pulled);
        return std::make_tuple(result, hose.points(), hose.attachmentGap(far));
    };
    const auto [result, points, gap] = run();
    EXPECT_EQ(result.status, Status::Infeasible);
    EXPECT_LE(result.lengthViolation, 1e-9) << "lengths are never given up";
    EXPECT_LE(result.angleViolation, 1e-9);
    for (const Vec3& p : points)
        EXPECT_TRUE(p.allFinite());
    EXPECT_NEAR(points[0].x(), 0.0, 1e-12) << "the attachment that did not move is met";
    // The free span 1 … 19 reaches 18 × 0.055 m = 0.99 m: point 19 at x = 0.05 + 0.99.
    EXPECT_NEAR(points[19].x(), 0.05 + 0.99, 1e-5);
    EXPECT_NEAR(gap, 1.45 - (0.05 + 0.99), 1e-5);
    for (int s = 1; s < 19; ++s) {
        EXPECT_NEAR((points[s + 1] - points[s]).norm(), 0.055, 1e-6) << s;
        EXPECT_NEAR(points[s].y(), 0.0, 1e-12);
        EXPECT_NEAR(points[s].z(), 0.0, 1e-12);
    }
    const auto [again, pointsAgain, gapAgain] = run();
    EXPECT_EQ(points, pointsAgain);
    EXPECT_EQ(gap, gapAgain);
}

// A straight inextensible hose whose end attachments come closer: on its line it cannot be
// shorter, so the span is first laid on the first buckling mode of a rod clamped at both pins,
// towards the fold-back rule's fixed perpendicular: +z for a span along +x (hose.h). Pushed far
// (0.3, 0.8 of its length) the mode's amplitude is found far from the straight line.
TEST(SolverHardCases, StraightInextensibleSpanPushedShorterBowsTowardsPlusZ)
{
    for (int segments : {10, 40})
        for (double push : {0.001, 0.01, 0.05, 0.3, 0.8}) {
            SCOPED_TRACE("segments " + std::to_string(segments) + ", push " + std::to_string(push));
            HoseSpec spec = paperSpec(segments, 0.0);
            spec.material.bendLimit = BendLimit::minBendRadius(0.1);
            Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
            hose.attach(0, 0, Frame::identity());
            const int end = hose.attach(segments, segments, Frame::identity());
            Frame closer;
            closer.translation = Vec3(-push, 0.0, 0.0);
            const UpdateResult result = hose.moveAttachment(end, closer);
            EXPECT_EQ(result.status, Status::Ok);
            EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
            double highest = 0.0;
            for (int i = 1; i < segments; ++i) {
                EXPECT_GT(hose.point(i).z(), 0.0) << i;
                EXPECT_NEAR(hose.point(i).y(), 0.0, 1e-12) << i;
                highest = std::max(highest, hose.point(i).z());
            }
            // The first buckling mode a (1 − cos 2πx/c) / 2 of length L over chord c = L − δ
            // rises a = (2/π) sqrt(δ c) (small δ).
            if (push <= 0.01) {
                const double rise = 2.0 / std::numbers::pi * std::sqrt(push * (1.0 - push));
                EXPECT_NEAR(highest, rise, 0.03 * rise);
            }
        }
}

// The same when the grabbed point pushes a straight span against its fixed end.
TEST(SolverHardCases, GrabPushingAStraightInextensibleSpanAgainstAPinBowsIt)
{
    HoseSpec spec = paperSpec(20, 0.0);
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    hose.attach(0, 0, Frame::identity());
    const UpdateResult result = hose.grab(10, Vec3(0.49, 0.0, 0.0));
    EXPECT_EQ(result.status, Status::Ok);
    EXPECT_LT(result.grabError, 1e-12);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    for (int i = 1; i < 10; ++i)
        EXPECT_GT(hose.point(i).z(), 0.0) << i;
}

// A rigid hose cannot bow: the request is decided from the straight state, as without the bow
// (Infeasible, the hose on its line).
TEST(SolverHardCases, RigidStraightSpanPushedShorterStaysOnItsLineAndIsInfeasible)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(10, 0.0, 0));
    hose.attach(0, 0, Frame::identity());
    const int end = hose.attach(10, 10, Frame::identity());
    Frame closer;
    closer.translation = Vec3(-0.01, 0.0, 0.0);
    EXPECT_EQ(hose.moveAttachment(end, closer).status, Status::Infeasible);
    EXPECT_TRUE(allFinite(hose));
    for (const Vec3& p : hose.points()) {
        EXPECT_EQ(p.y(), 0.0);
        EXPECT_EQ(p.z(), 0.0);
    }
}

TEST(SolverHardCases, GrabBetweenTwoAttachmentsReachesFeasibleTargetsAndClampsOthers)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(20, 0.1, 30));
    hose.attach(0, 1, Frame::identity());
    hose.attach(19, 20, Frame::identity());
    const UpdateResult feasible = hose.grab(10, Vec3(0.5, 0.12, 0.0));
    EXPECT_EQ(feasible.status, Status::Ok);
    EXPECT_LT(feasible.grabError, 1e-12);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);

    const UpdateResult tooFar = hose.grab(10, Vec3(0.5, 3.0, 0.0));
    EXPECT_EQ(tooFar.status, Status::Clamped);
    EXPECT_GT(tooFar.grabError, 2.0);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    EXPECT_GT(hose.point(10).y(), 0.12) << "moved towards the target as far as it can";
}

TEST(SolverHardCases, HoseFarFromTheOriginKeepsFullPrecision)
{
    const Vec3 far(1e5, -1e5, 1e5);
    Hose hose = Hose::straight(far, Vec3::UnitX(), 1.0, paperSpec(40, 0.1, 30));
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(-0.3, 0.3);
    for (int i = 0; i < 500; ++i) {
        const int index = std::uniform_int_distribution<int>(0, 40)(rng);
        const UpdateResult r =
            hose.grab(index, hose.point(index) + Vec3(unit(rng), unit(rng), unit(rng)));
        ASSERT_EQ(r.status, Status::Ok);
    }
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}

TEST(SolverHardCases, ExpansionZeroIsInextensible)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(25, 0.0, 45));
    static_cast<void>(hose.grab(12, Vec3(0.3, 0.4, 0.1)));
    static_cast<void>(hose.grab(0, Vec3(-0.2, 0.0, 0.3)));
    for (int s = 0; s < 25; ++s)
        EXPECT_NEAR((hose.point(s + 1) - hose.point(s)).norm(), 0.04, 1e-12);
}

TEST(SolverHardCases, DeflectionZeroIsRigid)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(25, 0.0, 0));
    static_cast<void>(hose.grab(12, Vec3(0.48, 0.3, 0.0)));
    static_cast<void>(hose.grab(25, Vec3(0.0, 2.0, 0.0)));
    const Vec3 direction = (hose.point(25) - hose.point(0)).normalized();
    for (int i = 0; i < 26; ++i) {
        const Vec3 offset = hose.point(i) - hose.point(0);
        EXPECT_LT((offset - offset.dot(direction) * direction).norm(), 1e-9) << i;
    }
    EXPECT_NEAR((hose.point(25) - hose.point(0)).norm(), 1.0, 1e-9);
}

TEST(SolverHardCases, OneAndTwoSegmentHoses)
{
    for (int segments : {1, 2}) {
        Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(segments, 0.1, 30));
        for (int i = 0; i <= segments; ++i) {
            const UpdateResult r = hose.grab(i, Vec3(0.1 * i, 0.5, -0.2 * i));
            EXPECT_EQ(r.status, Status::Ok);
            EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
        }
        hose.attach(0, 0, Frame::identity());
        const UpdateResult r = hose.grab(segments, Vec3(5.0, 0.0, 0.0));
        EXPECT_EQ(r.status, Status::Clamped);
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    }
}

TEST(SolverHardCases, TenThousandPointHose)
{
    HoseSpec spec;
    spec.segmentCount = 9999;
    spec.material.expansionCoefficient = 0.05;
    spec.material.bendLimit = BendLimit::minBendRadius(0.05);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 10.0, spec);
    EXPECT_EQ(hose.grab(5000, Vec3(5.0, 3.0, 1.0)).status, Status::Ok);
    EXPECT_EQ(hose.grab(0, Vec3(-1.0, 0.0, 0.0)).status, Status::Ok);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    hose.attach(9998, 9999, Frame::identity());
    EXPECT_NE(hose.grab(5000, Vec3(5.0, 50.0, 1.0)).status, Status::InvalidInput);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}

TEST(SolverHardCases, AMillionRandomDragsDoNotDrift)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(20, 0.1, 30));
    HoseSurface surface(hose);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> unit(-0.05, 0.05);
    std::uniform_int_distribution<int> pick(0, 20);
    double worstLength = 0.0, worstAngle = 0.0, worstFrame = 0.0;
    for (int i = 0; i < 1000000; ++i) {
        const int index = pick(rng);
        const Vec3 target = hose.point(index) + Vec3(unit(rng), unit(rng), unit(rng));
        ASSERT_EQ(hose.grab(index, target).status, Status::Ok) << i;
        if (i % 1000 == 0) {
            const Violation v = violation(hose);
            worstLength = std::max(worstLength, v.length);
            worstAngle = std::max(worstAngle, v.angle);
            surface.update(hose);
            for (const RingFrame& ring : surface.frames()) {
                worstFrame = std::max(worstFrame, std::abs(ring.alignment.norm() - 1.0));
                worstFrame = std::max(worstFrame, std::abs(ring.alignment.dot(ring.tangent)));
            }
        }
    }
    EXPECT_LE(worstLength, 1e-9);
    EXPECT_LE(worstAngle, 1e-9);
    EXPECT_LE(worstFrame, 1e-12) << "ring frames stay orthonormal (no twist drift)";
    EXPECT_LT(hose.point(0).norm(), 1e3) << "the hose stays bounded";
}

TEST(SolverHardCases, SetUpFunctionsRejectBadInputNamingTheField)
{
    auto expectMessage = [](auto&& call, const std::string& field) {
        try {
            call();
            ADD_FAILURE() << "no exception for " << field;
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
        }
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    HoseSpec spec = paperSpec();
    expectMessage([&] { BendLimit::deflectionAngle(std::numbers::pi); }, "deflectionAngle");
    expectMessage([&] { BendLimit::deflectionAngle(-0.1); }, "deflectionAngle");
    expectMessage([&] { BendLimit::minBendRadius(nan); }, "minBendRadius");
    spec.outerDiameter = -1;
    expectMessage([&] { Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1, spec); }, "outerDiameter");
    spec = paperSpec();
    spec.material.expansionCoefficient = 1.0;
    expectMessage([&] { Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1, spec); },
                  "expansionCoefficient");
    spec = paperSpec();
    expectMessage([&] { Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0, spec); }, "length");
    expectMessage([&] { Hose::straight(Vec3::Zero(), Vec3::Zero(), 1, spec); }, "direction");
    expectMessage([&] { Hose::straight(Vec3(nan, 0, 0), Vec3::UnitX(), 1, spec); }, "start");
    expectMessage([&] { Hose::alongRoute({Vec3::Zero()}, spec); }, "route");
    expectMessage([&] { Hose::alongRoute({Vec3::Zero(), Vec3::Zero()}, spec); }, "route[1]");
    spec.segmentCount = 2000000;
    expectMessage([&] { Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1, spec); }, "segmentCount");
    spec = paperSpec();
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1, spec);
    expectMessage([&] { hose.attach(5, 20, Frame::identity()); }, "attachment range");
    hose.attach(0, 3, Frame::identity());
    expectMessage([&] { hose.attach(3, 4, Frame::identity()); }, "already fixed");
}

TEST(SolverHardCases, PullingAFreeEndOutOfReachReachesTowardsTheTarget)
{
    HoseSpec spec = paperSpec(40, 0.0, 0);
    spec.material.bendLimit = BendLimit::minBendRadius(0.2);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    hose.attach(0, 1, Frame::identity());
    const Vec3 target(0.0, 5.0, 0.0); // far beyond reach, at right angles to the fixed start
    // Held for ten frames (a hand held still): every frame valid, never farther from the target.
    UpdateResult result;
    double error = (hose.point(40) - target).norm();
    for (int frame = 0; frame < 10; ++frame) {
        result = hose.grab(40, target);
        EXPECT_EQ(result.status, Status::Clamped);
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
        EXPECT_LE(result.grabError, error * (1 + 1e-12)) << frame;
        error = result.grabError;
    }
    // The hose bends towards the target as tightly as allowed and then points at it: the end is
    // much closer to the target than where it started (5.1 m away).
    EXPECT_LT(result.grabError, 4.3);
    const Vec3 lastDirection = (hose.point(40) - hose.point(39)).normalized();
    EXPECT_GT(lastDirection.dot((target - hose.point(40)).normalized()), 0.99);
}

TEST(SolverHardCases, AHoseRebuiltFromADeformedShapeKeepsItsRestLengths)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(10, 0.2, 40));
    static_cast<void>(hose.grab(
        10, Vec3(1.15, 0.0, 0.0))); // stretched: every segment longer than its rest length
    std::vector<double> rest;
    for (int s = 0; s < hose.segmentCount(); ++s)
        rest.push_back(hose.restLength(s));
    const Hose rebuilt = Hose::fromAxis(hose.points(), rest, hose.spec());
    for (int s = 0; s < hose.segmentCount(); ++s) {
        EXPECT_EQ(rebuilt.restLength(s), hose.restLength(s));
        EXPECT_DOUBLE_EQ(rebuilt.maxLength(s), hose.maxLength(s));
    }
    EXPECT_NEAR(measure(rebuilt).maxStretch, measure(hose).maxStretch, 1e-12);
    EXPECT_THROW(Hose::fromAxis(hose.points(), std::vector<double>(3, 0.1), hose.spec()),
                 InvalidArgument);
    EXPECT_THROW(Hose::fromAxis(hose.points(), std::vector<double>(10, -1.0), hose.spec()),
                 InvalidArgument);
}

// Grabs on a hose whose attachment is not met (its part moved beyond reach) keep every
// constraint and never meet the attachment by overstretching; bringing the part back meets it.
TEST(SolverHardCases, GrabsOnAHoseWithAnUnmetAttachmentKeepEveryConstraint)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec(20, 0.1, 30));
    hose.attach(0, 1, Frame::identity());
    const int far = hose.attach(19, 20, Frame::identity());
    Frame pulled;
    pulled.translation = Vec3(0.5, 0.0, 0.0); // ends 1.5 m apart, max length 1.1 m
    const UpdateResult apart = hose.moveAttachment(far, pulled);
    ASSERT_EQ(apart.status, Status::Infeasible);
    const double gap = hose.attachmentGap(far);
    EXPECT_GT(gap, 0.3);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        const int index = 2 + static_cast<int>(random() % 17);
        const Vec3 target =
            hose.point(index) + 0.3 * Vec3(unit(random), unit(random), unit(random));
        const UpdateResult r = hose.grab(index, target);
        ASSERT_NE(r.status, Status::InvalidInput);
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
        EXPECT_GE(hose.attachmentGap(far), gap - 1e-9) << "trial " << trial;
        for (const Vec3& p : hose.points())
            ASSERT_TRUE(p.allFinite());
    }
    // Bringing the part back within reach meets the attachment again; grabs are exact again.
    pulled.translation = Vec3::Zero();
    EXPECT_EQ(hose.moveAttachment(far, pulled).status, Status::Ok);
    EXPECT_EQ(hose.attachmentGap(far), 0.0);
    EXPECT_EQ(hose.grab(10, hose.point(10) + Vec3(0.0, 0.05, 0.0)).status, Status::Ok);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}
