// An end of a hose fixed at both ends, moved through translations and rotations in small
// steps (the way a part is dragged in the editor or moved in a VR scene): after every update
// every segment is inside its stretch band, and the reported status says what the measured
// state is (a met attachment and valid bends: Ok; an attachment left short or bends that gave
// way: Infeasible, with the gap and the bend excess it reports).
#include "test_util.h"

#include <cmath>
#include <gtest/gtest.h>
#include <string>

namespace chaintube {
namespace {

using test::violation;

constexpr double kDegree = 3.14159265358979323846 / 180.0;

struct SweepHose
{
    Hose hose;
    int far = -1; ///< the moved attachment
};

/// 30 segments, 0.8 m, ends fixed by two-point attachments 0.6 m apart along X.
SweepHose sweepHose(double expansion)
{
    HoseSpec spec;
    spec.outerDiameter = 0.02;
    spec.segmentCount = 30;
    spec.material.expansionCoefficient = expansion;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    SweepHose s{Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.05, 0, 0), Vec3(0.3, 0.2, 0),
                                  Vec3(0.55, 0, 0), Vec3(0.6, 0, 0)},
                                 spec),
                -1};
    s.hose.attach(0, 1, Frame::identity());
    s.far = s.hose.attach(29, 30, Frame::identity());
    return s;
}

/// Checks one update's result against the hose it left.
void expectHonest(const Hose& hose, int far, const UpdateResult& r, const std::string& where)
{
    const test::Violation v = violation(hose);
    EXPECT_LE(v.length, 1e-9) << where << ": a segment beyond its band";
    EXPECT_TRUE(test::allFinite(hose)) << where;
    const double gap = hose.attachmentGap(far);
    if (r.status == Status::Ok) {
        EXPECT_LE(v.angle, 1e-9) << where << ": Ok with a bend beyond its limit";
        EXPECT_LE(gap, 1e-9) << where << ": Ok with the attachment not met";
    } else {
        ASSERT_EQ(r.status, Status::Infeasible) << where;
        EXPECT_TRUE(gap > 1e-9 || v.angle > 1e-9) << where << ": Infeasible, but nothing is off";
        EXPECT_NEAR(r.angleViolation, std::max(v.angle, 0.0), 1e-9) << where;
    }
}

TEST(AttachmentSweep, TranslatedInAndBeyondReachAndBackEverySegmentStaysInItsBand)
{
    for (const double expansion : {0.0, 0.05}) {
        SweepHose s = sweepHose(expansion);
        const std::vector<Vec3> start = s.hose.points();
        bool wasShort = false;
        // 2 mm steps along +X to 0.4 m (the ends 1.0 m apart: beyond the 0.8 m hose), back to
        // −0.4 m (pushed together past each other's tangents) and back to the start.
        const int steps = 200;
        for (int i = 1; i <= 4 * steps; ++i) {
            const int phase = i / steps, within = i % steps;
            const double x = 0.4 * (phase == 0   ? double(within) / steps
                                    : phase == 1 ? 1.0 - 2.0 * within / steps
                                    : phase == 2 ? -1.0 + double(within) / steps
                                                 : 0.0);
            Frame frame;
            frame.translation = Vec3(x, 0.1 * std::sin(3.0 * x), 0.0);
            const UpdateResult r = s.hose.moveAttachment(s.far, frame);
            expectHonest(s.hose, s.far, r,
                         "expansion " + std::to_string(expansion) + ", x " + std::to_string(x));
            wasShort = wasShort || s.hose.attachmentGap(s.far) > 1e-3;
            if (::testing::Test::HasFailure()) return;
        }
        EXPECT_TRUE(wasShort) << "the sweep went beyond reach";
        // Back at the start: every attachment met, every constraint held.
        for (int again = 0; again < 4 && s.hose.attachmentGap(s.far) > 1e-9; ++again)
            static_cast<void>(s.hose.moveAttachment(s.far, Frame::identity()));
        EXPECT_LE(s.hose.attachmentGap(s.far), 1e-9);
        EXPECT_CONSTRAINTS_HOLD(s.hose, 1e-9);
        EXPECT_EQ(s.hose.point(29), start[29]);
    }
}

TEST(AttachmentSweep, TurnedAboutThreeAxesInTwoDegreeStepsEverySegmentStaysInItsBand)
{
    for (const Vec3& axis :
         {Vec3(Vec3::UnitZ()), Vec3(Vec3::UnitY()), Vec3(Vec3(1, 1, 0).normalized())}) {
        SweepHose s = sweepHose(0.02);
        // The end turned about its own point by up to 180° and back (a half turn points its
        // tangent back along the hose: the bends contradict and give way), then home.
        for (int i = 1; i <= 180; ++i) {
            const double angle = (i <= 90 ? i : 180 - i) * 2.0 * kDegree;
            Frame frame;
            const Vec3 pivot(0.6, 0.0, 0.0);
            frame.rotation = Quat(Eigen::AngleAxisd(angle, axis));
            frame.translation = pivot - frame.rotation * pivot;
            const UpdateResult r = s.hose.moveAttachment(s.far, frame);
            expectHonest(s.hose, s.far, r, "angle " + std::to_string(angle / kDegree) + "°");
            if (::testing::Test::HasFailure()) return;
        }
        EXPECT_LE(s.hose.attachmentGap(s.far), 1e-9);
        EXPECT_LE(violation(s.hose).length, 1e-9);
    }
}

/// The test rig's right hose (samples/test-rig.ctproj, "right-return": braided steel, 20
/// segments, 0.433 m, its route as laid there), fixed by one point at each end, its far end
/// moved along +X in 2 mm steps to 0.3 m and back, as the rig's valve is: wherever the ends are
/// within 99 % of the hose's reach, every update meets the moved end (the bends giving way
/// where they must, reported) within the attachment move's budget, and no segment ever leaves
/// its band.
TEST(AttachmentSweep, TheTestRigsRightHoseMeetsItsValveInEveryUpdateWithinReach)
{
    const std::vector<Vec3> route{Vec3(0.3, 0.21, 0.0),
                                  Vec3(0.283627, 0.2215987, 0.0081865),
                                  Vec3(0.2662909, 0.2312911, 0.0168546),
                                  Vec3(0.2481684, 0.2389784, 0.0259158),
                                  Vec3(0.2294447, 0.2445821, 0.0352776),
                                  Vec3(0.2103109, 0.248045, 0.0448446),
                                  Vec3(0.1909621, 0.2493317, 0.0545189),
                                  Vec3(0.171596, 0.2484291, 0.064202),
                                  Vec3(0.1524102, 0.2453464, 0.0737949),
                                  Vec3(0.1336005, 0.2401151, 0.0831997),
                                  Vec3(0.1153589, 0.2327886, 0.0923205),
                                  Vec3(0.0978716, 0.2234416, 0.1010642),
                                  Vec3(0.0813171, 0.2121696, 0.1093414),
                                  Vec3(0.0658644, 0.1990877, 0.1170678),
                                  Vec3(0.0516711, 0.1843292, 0.1241644),
                                  Vec3(0.0388822, 0.168045, 0.1305589),
                                  Vec3(0.0276282, 0.1504011, 0.1361859),
                                  Vec3(0.0180239, 0.1315777, 0.140988),
                                  Vec3(0.0101675, 0.1117669, 0.1449163),
                                  Vec3(0.004139, 0.0911709, 0.1479305),
                                  Vec3(0.0, 0.07, 0.15)};
    HoseSpec spec;
    spec.outerDiameter = 0.016;
    spec.segmentCount = 20;
    spec.material.expansionCoefficient = 0.01;
    spec.material.bendLimit = BendLimit::minBendRadius(0.165);
    Hose hose = Hose::fromAxis(route, std::vector<double>(20, 0.4334154350687771 / 20), spec);
    ASSERT_EQ(hose.measureViolation().status, Status::Ok);
    const int near = hose.attach(0, 0, Frame::identity());
    const int far = hose.attach(20, 20, Frame::identity());
    double reach = 0.0;
    for (int s = 0; s < hose.segmentCount(); ++s)
        reach += hose.maxLength(s);
    int met = 0, kinked = 0;
    for (int i = 1; i <= 299; ++i) {
        Frame frame;
        frame.translation = Vec3(0.002 * (i <= 150 ? i : 300 - i), 0.0, 0.0);
        const UpdateResult r = hose.moveAttachment(far, frame);
        const std::string where = "x " + std::to_string(frame.translation.x());
        expectHonest(hose, far, r, where);
        const double apart = (frame.apply(route.back()) - route.front()).norm();
        if (apart <= 0.99 * reach) {
            EXPECT_LE(hose.attachmentGap(far), 1e-6) << where << ": within reach, not met";
            ++met;
        }
        kinked += r.angleViolation > 1e-9;
        EXPECT_LE(hose.attachmentGap(near), 0.0) << where;
        // The attachment move's budget for one span (lib/README.md, "Budgets a call"): the
        // whole hose is one span between the two points, and no step is long enough to halve.
        EXPECT_LE(r.iterations, 2 * (3 * 12 + 8 + 8 + 4 + 8) + 2 * 12) << where;
        if (::testing::Test::HasFailure()) return;
    }
    EXPECT_GT(met, 100);
    EXPECT_GT(kinked, 0) << "the walk made the bends give way";
}

} // namespace
} // namespace chaintube
