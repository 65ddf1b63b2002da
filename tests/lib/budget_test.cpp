// A hard per-frame budget (Hose::setBudget, UpdateBudget): under it every update takes at most
// that many Newton steps, ends valid (every length and bend within 1e-9, no penetration), says
// whether its target is still pending, and step() goes on towards the same target frame by frame
// until it is met. Work is counted (UpdateResult::iterations), never timed.
#include "test_util.h"

#include <algorithm>
#include <cstdio>
#include <random>

using namespace chaintube;
using namespace chaintube::test;

namespace {

constexpr double kValid = 1e-9;

/// A hose of `points` points, 1 m long, bend radius 0.1 m, inextensible, laid as an arc whose
/// ends are 0.8 m apart in the plane y = 0, its end segments fixed.
Hose arcBetweenFixedEnds(int points, bool gravity = false)
{
    HoseSpec spec;
    spec.gravity.enabled = gravity;
    spec.segmentLength = 1.0 / (points - 1);
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    const double half = arcHalfAngle(0.8);
    const double radius = 0.5 / half;
    std::vector<Vec3> axis;
    for (int i = 0; i < points; ++i) {
        const double a = -half + 2.0 * half * i / (points - 1);
        axis.emplace_back(0.4 + radius * std::sin(a), 0.0,
                          -radius * (std::cos(a) - std::cos(half)));
    }
    Hose hose = Hose::fromAxis(axis, spec);
    hose.attach(0, 1, Frame::identity());
    hose.attach(points - 2, points - 1, Frame::identity());
    return hose;
}

/// As arcBetweenFixedEnds, laid as an S (two arcs of 0.5 m, the first bulging towards −z, the
/// second towards +z) with a sliding clip that never moves at the middle of the segment at a
/// quarter of its length: the real-time benchmark's ends-fixed-clip case.
Hose sCurveThroughAClip(int points)
{
    HoseSpec spec;
    spec.segmentLength = 1.0 / (points - 1);
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    const double half = arcHalfAngle(0.8);
    const double radius = 0.25 / half;
    std::vector<Vec3> axis;
    for (int i = 0; i < points; ++i) {
        const double s = static_cast<double>(i) / (points - 1);
        const bool second = s > 0.5;
        const double a = -half + 4.0 * half * (second ? s - 0.5 : s);
        axis.emplace_back((second ? 0.6 : 0.2) + radius * std::sin(a), 0.0,
                          (second ? 1.0 : -1.0) * radius * (std::cos(a) - std::cos(half)));
    }
    Hose hose = Hose::fromAxis(axis, spec);
    hose.attach(0, 1, Frame::identity());
    hose.attach(points - 2, points - 1, Frame::identity());
    const int segment = (points - 1) / 4;
    double place = 0.5 * hose.restLength(segment);
    for (int k = 0; k < segment; ++k)
        place += hose.restLength(k);
    static_cast<void>(hose.addClip(place, Frame::identity()));
    return hose;
}

std::shared_ptr<const MeshCollider> floorAt(double y)
{
    const std::vector<Vec3> corners = {Vec3(-2.0, y, -2.0), Vec3(3.0, y, -2.0), Vec3(3.0, y, 2.0),
                                       Vec3(-2.0, y, 2.0)};
    return MeshCollider::fromArrays(corners, {0, 2, 1, 0, 3, 2});
}

/// Every constraint holds to 1e-9 and every update stayed within `budget` Newton steps.
void expectValidWithin(const Hose& hose, const UpdateResult& result, int budget, int frame)
{
    const UpdateResult v = hose.measureViolation();
    EXPECT_LE(v.lengthViolation, kValid) << "frame " << frame;
    EXPECT_LE(v.angleViolation, kValid) << "frame " << frame;
    EXPECT_LE(result.iterations, budget) << "frame " << frame;
    EXPECT_TRUE(std::isfinite(result.remaining) && result.remaining >= 0.0) << "frame " << frame;
}

/// Frames of step() until nothing is pending (at most `limit`), each checked.
int framesUntilMet(Hose& hose, int budget, int limit)
{
    for (int frame = 1; frame <= limit; ++frame) {
        const UpdateResult r = hose.step();
        expectValidWithin(hose, r, budget, frame);
        if (!r.pending && !hose.pending()) return frame;
    }
    return limit + 1;
}

} // namespace

TEST(UpdateBudget, NoBudgetIsTheDefaultAndANegativeOneIsRefused)
{
    Hose hose = arcBetweenFixedEnds(50);
    EXPECT_FALSE(hose.budget().bounded());
    EXPECT_THROW(hose.setBudget(UpdateBudget{-1}), InvalidArgument);
    // Unbounded, a far grab is never pending.
    const UpdateResult r = hose.grab(25, hose.point(25) + Vec3(0.0, 0.15, 0.05));
    EXPECT_FALSE(r.pending);
    EXPECT_EQ(r.remaining, 0.0);
    EXPECT_FALSE(hose.pending());
    EXPECT_EQ(UpdateBudget::realtime().newtonSteps, UpdateBudget::kRealtimeNewtonSteps);
}

TEST(UpdateBudget, AFarGrabUnderASmallBudgetStaysValidAndMeetsItsTargetInBoundedFrames)
{
    constexpr int kBudget = 8;
    Hose bounded = arcBetweenFixedEnds(50);
    Hose unbounded = bounded;
    bounded.setBudget(UpdateBudget{kBudget});
    const Vec3 target = bounded.point(25) + Vec3(0.0, 0.15, 0.05); // within reach
    UpdateResult first = bounded.grab(25, target);
    expectValidWithin(bounded, first, kBudget, 0);
    EXPECT_TRUE(first.pending) << "a 16 cm grab takes more than 8 Newton steps";
    EXPECT_GT(first.remaining, 0.0);
    EXPECT_NEAR(first.remaining, (bounded.point(25) - target).norm(), 1e-12);
    const int frames = framesUntilMet(bounded, kBudget, 200);
    EXPECT_LE(frames, 200);
    // The unbounded grab, held: the same target met.
    for (int i = 0; i < 50 && (unbounded.point(25) - target).norm() > 1e-9; ++i)
        static_cast<void>(unbounded.grab(25, target));
    EXPECT_LE((unbounded.point(25) - target).norm(), 1e-6);
    EXPECT_LE((bounded.point(25) - unbounded.point(25)).norm(), 1e-6);
    // Met: the same target again costs nothing and is not pending.
    const UpdateResult again = bounded.grab(25, target);
    EXPECT_FALSE(again.pending);
    EXPECT_EQ(again.iterations, 0);
}

TEST(UpdateBudget, AGravityDropOntoAFloorUnderASmallBudgetStaysValidOutsideTheFloorAndComesToRest)
{
    constexpr int kBudget = 8;
    Hose bounded = arcBetweenFixedEnds(40, true);
    const double floorY = -0.05;
    bounded.setColliders({floorAt(floorY)});
    Hose unbounded = bounded;
    bounded.setBudget(UpdateBudget{kBudget});
    const double radius = bounded.outerRadius();
    const double tolerance = bounded.collisionOptions().tolerance;
    int pendingFrames = 0, frame = 0;
    for (; frame < 3000; ++frame) {
        const std::uint64_t revision = bounded.revision();
        const UpdateResult r = bounded.step();
        expectValidWithin(bounded, r, kBudget, frame);
        pendingFrames += r.pending;
        for (int i = 0; i < bounded.pointCount(); ++i)
            ASSERT_GE(bounded.point(i).y(), floorY + radius - tolerance - 1e-9)
                << "frame " << frame;
        if (!r.pending && bounded.revision() == revision) break;
    }
    EXPECT_LT(frame, 3000) << "comes to rest";
    for (int i = 0; i < 3000; ++i) {
        const std::uint64_t revision = unbounded.revision();
        static_cast<void>(unbounded.step());
        if (unbounded.revision() == revision) break;
    }
    // Both lie on the floor between the same ends: the same lowest height.
    double lowB = 1.0, lowU = 1.0;
    for (int i = 0; i < bounded.pointCount(); ++i) {
        lowB = std::min(lowB, bounded.point(i).y());
        lowU = std::min(lowU, unbounded.point(i).y());
    }
    EXPECT_NEAR(lowB, lowU, 1e-6);
}

TEST(UpdateBudget, UnderTheRealtimeDefaultAHeldTargetIsMetWithinTenFramesAfterAWalk)
{
    const int budget = UpdateBudget::kRealtimeNewtonSteps;
    for (const bool gravity : {false, true}) {
        SCOPED_TRACE(gravity ? "gravity" : "no gravity");
        Hose hose = arcBetweenFixedEnds(100, gravity);
        hose.setBudget(UpdateBudget::realtime());
        std::mt19937_64 random(20240901);
        std::uniform_real_distribution<double> unit(-1.0, 1.0);
        Vec3 target = hose.point(50);
        for (int frame = 0; frame < 300; ++frame) {
            Vec3 step(unit(random), unit(random), unit(random));
            target += 0.02 * step.normalized();
            target = target.cwiseMax(Vec3(0.34, 0.0, -0.18)).cwiseMin(Vec3(0.46, 0.18, 0.18));
            UpdateResult r = hose.grab(50, target);
            expectValidWithin(hose, r, budget, frame);
            if (gravity) {
                r = hose.step();
                expectValidWithin(hose, r, budget, frame);
            }
        }
        // Held still: each frame the same grab (and the step), met within 10 frames.
        int frames = 1;
        for (; frames <= 10; ++frames) {
            const UpdateResult grabbed = hose.grab(50, target);
            expectValidWithin(hose, grabbed, budget, frames);
            bool pending = grabbed.pending;
            if (gravity) {
                const UpdateResult stepped = hose.step();
                expectValidWithin(hose, stepped, budget, frames);
            }
            if (!pending) break;
        }
        EXPECT_LE(frames, 10);
    }
}

TEST(UpdateBudget, AnAttachmentWalkWithJumpsUnderTheRealtimeDefaultStaysValidAndMeetsItsFrame)
{
    // The end attachment of a 100-point hose walks 2 cm a frame and every 20th frame jumps
    // 20 cm (30 cm) and turns by up to 0.8 rad (1.2 rad): a part placed, as a scenario does.
    // Unbounded, a jump takes up to 49 (154) Newton steps; under the realtime budget each
    // update takes at most 16, ends valid, and a jump not met in its frame is met over the
    // next ones (the following attachment moves go on with it).
    const int budget = UpdateBudget::kRealtimeNewtonSteps;
    for (const double jump : {0.2, 0.3}) {
        SCOPED_TRACE("jump " + std::to_string(jump));
        Hose bounded = arcBetweenFixedEnds(100);
        Hose unbounded = bounded;
        bounded.setBudget(UpdateBudget::realtime());
        const int id = bounded.attachments().back().id;
        std::mt19937_64 random(20240902);
        std::uniform_real_distribution<double> unit(-1.0, 1.0);
        Frame frame = Frame::identity();
        int pendingFrames = 0, longestRun = 0, run = 0, unboundedMost = 0;
        for (int f = 0; f < 300; ++f) {
            const Vec3 step(unit(random), unit(random), unit(random));
            frame.translation += (f % 20 == 19 ? jump : 0.02) * step.normalized();
            frame.translation = frame.translation.cwiseMax(Vec3(-0.3, -0.15, -0.15))
                                    .cwiseMin(Vec3(0.05, 0.15, 0.15)); // within reach
            frame.rotation =
                Quat(Eigen::AngleAxisd(4.0 * jump * std::sin((f / 20) * 1.3), Vec3::UnitY())) *
                Quat(Eigen::AngleAxisd(2.0 * jump * std::cos((f / 20) * 0.7), Vec3::UnitX()));
            const UpdateResult r = bounded.moveAttachment(id, frame);
            expectValidWithin(bounded, r, budget, f);
            EXPECT_EQ(r.pending, bounded.pending()) << "frame " << f;
            if (r.pending) {
                EXPECT_NEAR(r.remaining, bounded.attachmentGap(id), 1e-12) << "frame " << f;
                EXPECT_NEAR(bounded.remaining(), r.remaining, 1e-12) << "frame " << f;
                EXPECT_EQ(r.status, Status::Ok) << "frame " << f;
            } else {
                EXPECT_LE(bounded.attachmentGap(id), 1e-9) << "frame " << f;
            }
            run = r.pending ? run + 1 : 0;
            pendingFrames += r.pending;
            longestRun = std::max(longestRun, run);
            unboundedMost = std::max(unboundedMost, unbounded.moveAttachment(id, frame).iterations);
        }
        EXPECT_GT(unboundedMost, budget) << "the walk needs more than the budget somewhere";
        EXPECT_GT(pendingFrames, 0);
        EXPECT_LE(longestRun, 30) << "a jump is met within 30 frames of walking on";
        // A last jump, then held still: step() goes on with it, met within 10 frames.
        frame.translation = Vec3(-0.25, 0.12, 0.1);
        frame.rotation = Quat(Eigen::AngleAxisd(-2.0 * jump, Vec3::UnitY()));
        const UpdateResult jumped = bounded.moveAttachment(id, frame);
        expectValidWithin(bounded, jumped, budget, 300);
        EXPECT_LE(framesUntilMet(bounded, budget, 10), 10);
        EXPECT_LE(bounded.attachmentGap(id), 1e-9);
        EXPECT_FALSE(bounded.pending());
        EXPECT_EQ(bounded.remaining(), 0.0);
        static_cast<void>(unbounded.moveAttachment(id, frame));
        // The same end state as the unbounded solver: the attachment's points where its frame
        // puts them (the free points between keep the shape their own path left them in).
        for (int i = bounded.attachments().back().first; i <= bounded.attachments().back().last;
             ++i)
            EXPECT_LE((bounded.point(i) - unbounded.point(i)).norm(), 1e-3);
    }
}

TEST(UpdateBudget, AJumpOfAnAttachmentFinishedPendingIsMetAtOnce)
{
    Hose hose = arcBetweenFixedEnds(100);
    hose.setBudget(UpdateBudget{4});
    const int id = hose.attachments().back().id;
    Frame frame = Frame::identity();
    frame.translation = Vec3(-0.25, 0.12, 0.1);
    frame.rotation = Quat(Eigen::AngleAxisd(-0.5, Vec3::UnitY()));
    const UpdateResult jumped = hose.moveAttachment(id, frame);
    expectValidWithin(hose, jumped, 4, 0);
    ASSERT_TRUE(jumped.pending);
    EXPECT_GT(hose.remaining(), 0.0);
    // The editor's commit: one unbounded update meets the frame.
    const UpdateResult finished = hose.finishPending();
    EXPECT_FALSE(finished.pending);
    EXPECT_EQ(finished.status, Status::Ok);
    EXPECT_FALSE(hose.pending());
    EXPECT_LE(hose.attachmentGap(id), 1e-9);
    const UpdateResult v = hose.measureViolation();
    EXPECT_LE(v.lengthViolation, kValid);
    EXPECT_LE(v.angleViolation, kValid);
}

TEST(UpdateBudget, ThroughAClipAHeldTargetBeyondReachComesToRestWithinTenFramesAfterAWalk)
{
    // The middle walks 2 cm a frame for 300 frames in a box about half of which is beyond its
    // reach, then is held still. Under the real-time budget a held target the span can only
    // creep towards (along the edge of its reach, or not at all from this shape) stops being
    // pending once three grabs in a row gained less than 1 % of the error: it rests, Clamped,
    // and the same grab again costs nothing.
    const int budget = UpdateBudget::kRealtimeNewtonSteps;
    for (const int points : {25, 100, 400}) {
        SCOPED_TRACE(std::to_string(points) + " points");
        Hose hose = sCurveThroughAClip(points);
        hose.setBudget(UpdateBudget::realtime());
        const int middle = points / 2;
        std::mt19937_64 random(20240901);
        std::uniform_real_distribution<double> unit(-1.0, 1.0);
        Vec3 target = hose.point(middle);
        for (int frame = 0; frame < 300; ++frame) {
            Vec3 step(unit(random), unit(random), unit(random));
            target += 0.02 * step.normalized();
            target = target.cwiseMax(Vec3(0.34, 0.0, -0.18)).cwiseMin(Vec3(0.46, 0.18, 0.18));
            expectValidWithin(hose, hose.grab(middle, target), budget, frame);
        }
        int frames = 1;
        UpdateResult held;
        for (; frames <= 10; ++frames) {
            held = hose.grab(middle, target);
            expectValidWithin(hose, held, budget, frames);
            if (!held.pending) break;
        }
        EXPECT_LE(frames, 10);
        EXPECT_FALSE(hose.pending());
        EXPECT_NE(held.status, Status::InvalidInput);
        EXPECT_NEAR(held.grabError, (hose.point(middle) - target).norm(), 1e-12);
        // At rest: the same grab again moves nothing.
        const std::vector<Vec3> resting = hose.points();
        const UpdateResult again = hose.grab(middle, target);
        expectValidWithin(hose, again, budget, frames + 1);
        EXPECT_FALSE(again.pending);
        EXPECT_LE((hose.point(middle) - target).norm(), held.grabError + 1e-12);
    }
}

namespace {

/// A straight hose of `points` points along +x, `length` long, bend radius 0.1 m, inextensible,
/// its end segments fixed (the attachments' frames the identity).
Hose straightBetweenFixedEnds(int points, double length)
{
    HoseSpec spec;
    spec.segmentLength = length / (points - 1);
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    std::vector<Vec3> axis;
    for (int i = 0; i < points; ++i)
        axis.emplace_back(length * i / (points - 1), 0.0, 0.0);
    Hose hose = Hose::fromAxis(axis, spec);
    hose.attach(0, 1, Frame::identity());
    hose.attach(points - 2, points - 1, Frame::identity());
    return hose;
}

} // namespace

TEST(UpdateBudget, AnEndTurnedFarOffItsAxisGivesWayWithinTheBudgetAndMeetsItsFrame)
{
    // The end attachment of a straight 0.5 m hose (30 points, bend radius 0.1 m) turned by 1.5
    // to 3.14 rad about y and brought 0.1 to 0.3 m back towards the other end: unbounded, the
    // move lets the bends give way (Infeasible, up to 2.9 rad), in 58 to 324 Newton steps.
    // Under the real-time budget the tries that keep the bends creep or find nothing; after 2
    // such updates the bends give way within the budget: every update within it, every length
    // in its band, the frame met, and the move no longer pending.
    const int budget = UpdateBudget::kRealtimeNewtonSteps;
    std::vector<int> work;
    int slowest = 0, unboundedMost = 0;
    for (const double turn : {1.5, 2.0, 2.5, 3.0, 3.14})
        for (const double back : {0.1, 0.2, 0.3}) {
            SCOPED_TRACE("turn " + std::to_string(turn) + ", back " + std::to_string(back));
            Hose bounded = straightBetweenFixedEnds(30, 0.5);
            Hose unbounded = bounded;
            bounded.setBudget(UpdateBudget::realtime());
            const int id = bounded.attachments().back().id;
            Frame frame;
            frame.rotation = Quat(Eigen::AngleAxisd(turn, Vec3::UnitY()));
            // The end point (0.5, 0, 0) goes to (0.5 − back, 0, 0.05).
            frame.translation = Vec3(0.5 - back, 0.0, 0.05) - frame.rotation * Vec3(0.5, 0.0, 0.0);
            const UpdateResult u = unbounded.moveAttachment(id, frame);
            unboundedMost = std::max(unboundedMost, u.iterations);
            EXPECT_EQ(u.status, Status::Infeasible);
            UpdateResult r = bounded.moveAttachment(id, frame);
            work.push_back(r.iterations);
            int frames = 0;
            for (; frames < 30 && bounded.pending(); ++frames) {
                EXPECT_LE(bounded.measureViolation().lengthViolation, kValid) << frames;
                r = bounded.step();
                work.push_back(r.iterations);
                EXPECT_LE(r.iterations, budget) << frames;
            }
            slowest = std::max(slowest, frames);
            EXPECT_FALSE(bounded.pending());
            EXPECT_LE(bounded.attachmentGap(id), 1e-6);
            EXPECT_LE(bounded.measureViolation().lengthViolation, kValid);
            // The bends gave way, said so.
            EXPECT_EQ(r.status, Status::Infeasible);
            EXPECT_GT(r.angleViolation, 0.0);
            EXPECT_NEAR(r.angleViolation, bounded.measureViolation().angleViolation, 1e-12);
            // Held there, the hose stays valid in its lengths and costs no more than the budget.
            for (int more = 0; more < 10; ++more) {
                const UpdateResult held = bounded.moveAttachment(id, frame);
                EXPECT_LE(held.iterations, budget);
                EXPECT_LE(bounded.measureViolation().lengthViolation, kValid);
                EXPECT_LE(bounded.attachmentGap(id), 1e-6);
            }
        }
    EXPECT_LE(*std::max_element(work.begin(), work.end()), budget);
    std::sort(work.begin(), work.end());
    std::printf("[ figures ] an end turned far off its axis, realtime budget: work an update worst "
                "%d median %d Newton steps (unbounded up to %d in one), met within %d updates\n",
                work.back(), work[work.size() / 2], unboundedMost, slowest + 1);
}

TEST(UpdateBudget, AGravityStepThatFindsNothingValidWithinTheBudgetRestsAfterThreeSteps)
{
    // A 100-point arc under gravity whose steps need far more than 1 Newton step: each step()
    // is cut short with nothing valid and stays pending, then the hose rests where it is after
    // the third, as without a budget (an input wakes it).
    Hose hose = arcBetweenFixedEnds(100, true);
    const std::vector<Vec3> start = hose.points();
    hose.setBudget(UpdateBudget{1});
    int steps = 0;
    for (; steps < 10; ++steps) {
        const UpdateResult r = hose.step();
        EXPECT_LE(r.iterations, 1);
        EXPECT_LE(hose.measureViolation().lengthViolation, kValid);
        EXPECT_LE(hose.measureViolation().angleViolation, kValid);
        EXPECT_EQ(r.pending, hose.pending());
        if (!r.pending) break;
    }
    EXPECT_EQ(steps, 2) << "pending for the first two steps, at rest after the third";
    const std::uint64_t revision = hose.revision();
    const UpdateResult rest = hose.step();
    EXPECT_EQ(rest.iterations, 0);
    EXPECT_FALSE(rest.pending);
    EXPECT_EQ(hose.revision(), revision);
    // A move of an attachment wakes it: gravity steps again.
    Frame frame = Frame::identity();
    frame.translation = Vec3(-0.01, 0.0, 0.0);
    static_cast<void>(hose.moveAttachment(hose.attachments().back().id, frame));
    EXPECT_GT(hose.step().iterations, 0);
    // Under the real-time budget it falls, frame by frame, each within the budget.
    Hose falling = arcBetweenFixedEnds(100, true);
    falling.setBudget(UpdateBudget::realtime());
    int worst = 0;
    for (int step = 0; step < 200; ++step)
        worst = std::max(worst, falling.step().iterations);
    EXPECT_LE(worst, UpdateBudget::kRealtimeNewtonSteps);
    EXPECT_LT(falling.point(50).y(), start[50].y() - 0.01);
}
