// Reeling a hose in and paying it out at an end or through a clip (chaintube/reel.h).
#include "test_util.h"

#include <iostream>
#include <limits>

using namespace chaintube;
using namespace chaintube::test;

namespace {

constexpr double kFrame = 1.0 / 90.0;
constexpr double kSpeed = 0.5; // metres a second

HoseSpec reelSpec()
{
    HoseSpec spec;
    spec.segmentLength = 0.02;
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.05);
    return spec;
}

/// Where each point of the hose before a reel call is after it: the outlet (a pinned point,
/// index before the call) and the side its free hose is on; a point inserted next to the
/// outlet has no source, a removed one no image (−1).
std::vector<int> imageOf(int pointsBefore, int outlet, int side, const ReelResult& r)
{
    std::vector<int> image(static_cast<size_t>(pointsBefore));
    for (int i = 0; i < pointsBefore; ++i) {
        int to = i;
        if (r.segmentsAdded == 1) {
            const int inserted = side > 0 ? outlet + 1 : outlet;
            if (i >= inserted) ++to;
        } else if (r.segmentsRemoved == 1) {
            const int removed = outlet + side;
            if (i == removed)
                to = -1;
            else if (i > removed)
                --to;
        }
        image[static_cast<size_t>(i)] = to;
    }
    return image;
}

struct Walk
{
    double paidOut = 0.0;
    double paidIn = 0.0;
    double largestMoveOverPaid = 0.0; ///< the largest point move of a frame / its |paid|
    double worstLength = 0.0;         ///< the largest length violation after a frame (relative)
    double worstAngle = 0.0;          ///< the largest bend violation after a frame (radians)
    int mostIterations = 0;           ///< Newton steps of the costliest frame
    int iterations = 0;               ///< Newton steps of all frames
    int frames = 0;
    int framesValid = 0;
};

/// Pays out `distance` at kSpeed a frame, then reels it back in (`first` −1: in, then out),
/// checking after every frame: the constraints hold, no point moved farther than `moveFactor`
/// times what the frame paid, the total rest length is the start's plus what was paid.
/// `outletOf` gives the outlet point and side before a call.
template <typename Call, typename OutletOf>
Walk payOutAndBack(Hose& hose, double distance, Call call, OutletOf outletOf, int first = +1,
                   double moveFactor = 1.0)
{
    Walk walk;
    const double total0 = hose.restLengthTotal();
    double paid = 0.0;
    for (int direction : {first, -first}) {
        double left = distance;
        while (left > 1e-12) {
            const double ask = std::min(left, kSpeed * kFrame);
            const std::vector<Vec3> before = hose.points();
            const auto [outlet, side] = outletOf(hose);
            const ReelResult r = call(hose, direction * ask);
            EXPECT_EQ(r.status, Status::Ok) << r.message;
            EXPECT_NEAR(r.paid, direction * ask, 1e-15);
            left -= std::abs(r.paid);
            paid += r.paid;
            (direction > 0 ? walk.paidOut : walk.paidIn) += std::abs(r.paid);
            ++walk.frames;
            EXPECT_TRUE(allFinite(hose));
            const Violation v = violation(hose);
            const bool valid =
                v.length <= 1e-9 && v.angle <= 1e-9 && hose.measureViolation().status == Status::Ok;
            walk.framesValid += valid;
            walk.worstLength = std::max(walk.worstLength, v.length);
            walk.worstAngle = std::max(walk.worstAngle, v.angle);
            walk.mostIterations = std::max(walk.mostIterations, r.update.iterations);
            walk.iterations += r.update.iterations;
            EXPECT_NEAR(hose.restLengthTotal(), total0 + paid, 1e-9);
            const std::vector<int> image =
                imageOf(static_cast<int>(before.size()), outlet, side, r);
            EXPECT_EQ(static_cast<int>(before.size()) + r.segmentsAdded - r.segmentsRemoved,
                      hose.pointCount());
            if (static_cast<int>(before.size()) + r.segmentsAdded - r.segmentsRemoved !=
                hose.pointCount())
                return walk;
            double largest = 0.0;
            for (size_t i = 0; i < before.size(); ++i)
                if (image[i] >= 0)
                    largest = std::max(largest, (hose.point(image[i]) - before[i]).norm());
            EXPECT_LE(largest, moveFactor * std::abs(r.paid) * (1.0 + 1e-9) + 1e-12);
            EXPECT_LE(largest, r.largestMove * (1.0 + 1e-9) + 1e-15);
            walk.largestMoveOverPaid =
                std::max(walk.largestMoveOverPaid, largest / std::abs(r.paid));
            if (r.paid == 0.0) return walk; // stuck: reported above
        }
    }
    return walk;
}

std::pair<int, int> startOutlet(const Hose& hose)
{
    return {hose.attachments().front().last, +1};
}

} // namespace

TEST(Reel, PayingOutAtAnEndAndBackKeepsEveryFrameValidAndNoPointJumps)
{
    // A hose fixed at its start (end segment in the reel's outlet) running along x, then down:
    // its free end hangs.
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.4, 0, 0), Vec3(0.4, -0.4, 0)}, reelSpec());
    const int segments = hose.segmentCount();
    const double total0 = hose.restLengthTotal();
    std::vector<double> rest;
    for (int s = 0; s < segments; ++s)
        rest.push_back(hose.restLength(s));
    hose.attach(0, 1, Frame::identity());
    const Vec3 p0 = hose.point(0), p1 = hose.point(1);
    const Walk walk = payOutAndBack(
        hose, 0.3, [](Hose& h, double l) { return reel(h, HoseEnd::Start, l, 0.0, 10.0); },
        startOutlet);
    EXPECT_EQ(walk.frames, 2 * 54);
    EXPECT_EQ(walk.framesValid, walk.frames);
    EXPECT_NEAR(walk.paidOut, 0.3, 1e-12);
    EXPECT_NEAR(walk.paidIn, 0.3, 1e-12);
    // Back where it began: the segments, the length, the attachment's points.
    EXPECT_EQ(hose.segmentCount(), segments);
    EXPECT_NEAR(hose.restLengthTotal(), total0, 1e-9);
    EXPECT_EQ(hose.point(0), p0);
    EXPECT_EQ(hose.point(1), p1);
    EXPECT_EQ(hose.attachments().front().first, 0);
    EXPECT_EQ(hose.attachments().front().last, 1);
    // The segments beyond the outlet's kept their rest lengths.
    for (int s = 2; s < hose.segmentCount(); ++s)
        EXPECT_EQ(hose.restLength(s), rest[static_cast<size_t>(s)]) << s;
    EXPECT_NEAR(hose.restLength(1), rest[1], 1e-9);
}

TEST(Reel, PayingOutAtTheLastPointMovesTheEndAttachmentIndicesAndAddsPointsThere)
{
    Hose hose = Hose::alongRoute({Vec3(0.4, -0.4, 0), Vec3(0.4, 0, 0), Vec3(0, 0, 0)}, reelSpec());
    const int n = hose.pointCount() - 1;
    const int segments = hose.segmentCount();
    const Vec3 end = hose.point(n);
    hose.attach(n - 1, n, Frame::identity());
    auto endOutlet = [](const Hose& h) {
        return std::pair<int, int>{h.attachments().front().first, -1};
    };
    // Out 0.1 m: five more segments (at 20 mm each) between the free start and the outlet.
    double paid = 0.0;
    int added = 0;
    for (int frame = 0; frame < 18; ++frame) {
        const ReelResult r = reel(hose, HoseEnd::End, kSpeed * kFrame, 0.0, 10.0);
        ASSERT_EQ(r.status, Status::Ok) << r.message;
        paid += r.paid;
        added += r.segmentsAdded;
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    }
    EXPECT_NEAR(paid, 0.1, 1e-12);
    EXPECT_EQ(added, hose.segmentCount() - segments);
    EXPECT_GE(added, 4);
    EXPECT_EQ(hose.point(hose.pointCount() - 1), end);
    EXPECT_EQ(hose.attachments().front().last, hose.pointCount() - 1);
    const Walk walk = payOutAndBack(
        hose, 0.1, [](Hose& h, double l) { return reel(h, HoseEnd::End, l, 0.0, 10.0); }, endOutlet,
        -1);
    EXPECT_EQ(walk.framesValid, walk.frames);
    EXPECT_EQ(hose.segmentCount(), segments + added);
}

TEST(Reel, ThroughAClipOutletTheDrumSideStaysAndTheLengthAppearsAtTheClip)
{
    // A hose through a clip at 0.2 m, turning down beyond it to a free end; its start (the drum
    // side) is free too.
    Hose hose =
        Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.45, 0, 0), Vec3(0.45, -0.3, 0)}, reelSpec());
    const int clip = hose.addClip(0.2, Frame::identity());
    const int segments = hose.segmentCount();
    const double total0 = hose.restLengthTotal();
    const double slide0 = hose.attachments().back().slide;
    const int clipLast = hose.attachments().back().last;
    std::vector<Vec3> drum;
    for (int i = 0; i <= clipLast; ++i)
        drum.push_back(hose.point(i));
    auto clipOutlet = [clip](const Hose& h) {
        for (const Hose::Attachment& a : h.attachments())
            if (a.id == clip) return std::pair<int, int>{a.last, +1};
        return std::pair<int, int>{-1, +1};
    };
    auto reelAtClip = [clip](Hose& h, double l) {
        return reelThroughClip(h, clip, HoseEnd::Start, l, 0, 10);
    };
    int most = segments;
    const Walk walk = payOutAndBack(
        hose, 0.3,
        [&](Hose& h, double l) {
            const ReelResult r = reelAtClip(h, l);
            most = std::max(most, h.segmentCount());
            return r;
        },
        clipOutlet);
    EXPECT_EQ(walk.frames, 2 * 54);
    EXPECT_EQ(walk.framesValid, walk.frames);
    EXPECT_GE(most, segments + 14); // 0.3 m of 20 mm segments, the one at the outlet up to 1.5
    EXPECT_EQ(hose.segmentCount(), segments);
    EXPECT_NEAR(hose.restLengthTotal(), total0, 1e-9);
    // The drum side and the clip did not move.
    for (int i = 0; i <= clipLast; ++i)
        EXPECT_EQ(hose.point(i), drum[static_cast<size_t>(i)]) << i;
    EXPECT_EQ(hose.attachments().back().slide, slide0);
}

TEST(Reel, IntoASpanToAFixedPartTheSagChangesWithTheLengthWithinTwiceThePaidLength)
{
    // The same clip, the hose beyond it fixed to a part below with slack: the span between the
    // clip and the part takes the length by its shape (span solver).
    Hose hose = Hose::alongRoute(
        {Vec3(0, 0, 0), Vec3(0.45, 0, 0), Vec3(0.45, -0.3, 0), Vec3(0.7, -0.3, 0)}, reelSpec());
    const int n = hose.pointCount() - 1;
    const int part = hose.attach(n - 1, n, Frame::identity());
    ASSERT_EQ(hose.moveAttachment(part, translated(Vec3(-0.1, 0.05, 0))).status, Status::Ok);
    const int clip = hose.addClip(0.2, Frame::identity());
    const int segments = hose.segmentCount();
    auto clipOutlet = [clip](const Hose& h) {
        for (const Hose::Attachment& a : h.attachments())
            if (a.id == clip) return std::pair<int, int>{a.last, +1};
        return std::pair<int, int>{-1, +1};
    };
    const Walk walk = payOutAndBack(
        hose, 0.1,
        [clip](Hose& h, double l) { return reelThroughClip(h, clip, HoseEnd::Start, l, 0, 10); },
        clipOutlet, +1, 2.0);
    EXPECT_EQ(walk.framesValid, walk.frames);
    EXPECT_NEAR(walk.paidOut, 0.1, 1e-12);
    EXPECT_NEAR(walk.paidIn, 0.1, 1e-12);
    EXPECT_EQ(hose.segmentCount(), segments);
    EXPECT_LE(hose.attachmentGap(part), 1e-9);
    // Measured: the span's middle moves about 1.2 times the length paid a frame.
    EXPECT_GT(walk.largestMoveOverPaid, 1.0);
}

TEST(Reel, AStraightTautSpanCannotTakeMoreLengthAndSaysSo)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.4, reelSpec());
    hose.attach(0, 1, Frame::identity());
    const int n = hose.pointCount() - 1;
    hose.attach(n, n, translated(Vec3::Zero()));
    const std::vector<Vec3> points = hose.points();
    const ReelResult r = reel(hose, HoseEnd::Start, 0.005, 0, 1);
    EXPECT_EQ(r.status, Status::Clamped);
    EXPECT_EQ(r.paid, 0.0);
    EXPECT_FALSE(r.message.empty());
    EXPECT_EQ(hose.points(), points);
    EXPECT_NEAR(hose.restLengthTotal(), 0.4, 1e-12);
}

TEST(Reel, TheLengthBoundsClampAndSaySo)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.4, reelSpec());
    hose.attach(0, 0, Frame::identity());
    const double total0 = hose.restLengthTotal();
    // Out at most to 0.45 m: 0.03 m asked, 0.03 paid; then 0.03 asked, 0.02 paid, Clamped.
    ReelResult r = reel(hose, HoseEnd::Start, 0.03, 0.3, 0.45);
    EXPECT_EQ(r.status, Status::Ok);
    r = reel(hose, HoseEnd::Start, 0.03, 0.3, 0.45);
    EXPECT_EQ(r.status, Status::Clamped);
    EXPECT_TRUE(r.clamped);
    EXPECT_NEAR(r.paid, 0.02, 1e-12);
    EXPECT_NEAR(hose.restLengthTotal(), 0.45, 1e-12);
    EXPECT_NE(r.message.find("maximum"), std::string::npos) << r.message;
    r = reel(hose, HoseEnd::Start, 0.01, 0.3, 0.45);
    EXPECT_EQ(r.status, Status::Clamped);
    EXPECT_EQ(r.paid, 0.0);
    // In to the minimum 0.3 m, in steps of the frame.
    double paid = 0.0;
    for (int frame = 0; frame < 40; ++frame) {
        r = reel(hose, HoseEnd::Start, -kSpeed * kFrame, 0.3, 0.45);
        paid += r.paid;
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    }
    EXPECT_EQ(r.status, Status::Clamped);
    EXPECT_NE(r.message.find("minimum"), std::string::npos) << r.message;
    EXPECT_NEAR(hose.restLengthTotal(), 0.3, 1e-12);
    EXPECT_NEAR(paid, 0.3 - 0.45, 1e-12);
    EXPECT_NEAR(total0 + 0.05 + paid, 0.3, 1e-12);
}

TEST(Reel, BadInputIsRejectedAndChangesNothing)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.4, reelSpec());
    const int fixed = hose.attach(0, 1, Frame::identity());
    const int clip = hose.addClip(0.3, Frame::identity());
    const std::vector<Vec3> points = hose.points();
    const std::uint64_t revision = hose.revision();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    struct Case
    {
        ReelResult result;
        const char* names;
    };
    const Case cases[] = {
        {reel(hose, HoseEnd::Start, nan, 0, 1), "reel length"},
        {reel(hose, HoseEnd::Start, inf, 0, 1), "reel length"},
        {reel(hose, HoseEnd::Start, 0.01, -0.1, 1), "minLength"},
        {reel(hose, HoseEnd::Start, 0.01, nan, 1), "minLength"},
        {reel(hose, HoseEnd::Start, 0.01, 0.5, 0.4), "maxLength"},
        {reel(hose, HoseEnd::Start, 0.01, 0.0, nan), "maxLength"},
        {reel(hose, HoseEnd::End, 0.01, 0, 1), "reel end end"}, // a free end: no reel
        {reelThroughClip(hose, fixed, HoseEnd::Start, 0.01, 0, 1), "fixed attachment"},
        {reelThroughClip(hose, 99, HoseEnd::Start, 0.01, 0, 1), "no such id"},
    };
    for (const Case& c : cases) {
        EXPECT_EQ(c.result.status, Status::InvalidInput) << c.names;
        EXPECT_EQ(c.result.paid, 0.0);
        EXPECT_NE(c.result.message.find(c.names), std::string::npos) << c.result.message;
    }
    EXPECT_EQ(hose.points(), points);
    EXPECT_EQ(hose.revision(), revision);
    // Zero: nothing to do, Ok. An infinite maximum is no bound.
    EXPECT_EQ(reel(hose, HoseEnd::Start, 0.0, 0, 1).status, Status::Ok);
    EXPECT_EQ(hose.revision(), revision);
    EXPECT_EQ(reelThroughClip(hose, clip, HoseEnd::Start, 0.01, 0, inf).status, Status::Ok);
    EXPECT_NEAR(hose.restLengthTotal(), 0.41, 1e-12);
}

TEST(Reel, TwoPointsLeftTheLastSegmentStopsAtHalfItsRestLength)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.02, reelSpec());
    ASSERT_EQ(hose.pointCount(), 2);
    hose.attach(0, 0, Frame::identity());
    ReelResult r = reel(hose, HoseEnd::Start, -0.004, 0.0, 1.0);
    EXPECT_EQ(r.status, Status::Ok);
    r = reel(hose, HoseEnd::Start, -0.01, 0.0, 1.0);
    EXPECT_EQ(r.status, Status::Clamped);
    EXPECT_NEAR(hose.restLengthTotal(), 0.01, 1e-12);
    EXPECT_NE(r.message.find("half its rest length"), std::string::npos) << r.message;
    r = reel(hose, HoseEnd::Start, -0.001, 0.0, 1.0);
    EXPECT_EQ(r.paid, 0.0);
    EXPECT_EQ(hose.pointCount(), 2);
    // Paid out again, the hose grows at the outlet in 10 mm steps, splitting its one segment.
    for (int k = 0; k < 10; ++k) {
        r = reel(hose, HoseEnd::Start, 0.01, 0.0, 1.0);
        ASSERT_EQ(r.status, Status::Ok) << r.message;
        EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    }
    EXPECT_NEAR(hose.restLengthTotal(), 0.11, 1e-12);
    EXPECT_GE(hose.pointCount(), 5);
    EXPECT_NEAR((hose.point(hose.pointCount() - 1) - hose.point(0)).norm(), 0.11, 1e-12);
}

TEST(Reel, AHeldEndPinsTheSpanBeyondTheOutletAndStaysHeld)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.4, reelSpec());
    hose.attach(0, 0, Frame::identity());
    const int last = hose.pointCount() - 1;
    ASSERT_EQ(hose.grab(last, hose.point(last) + Vec3(0, 0.0, 0)).status, Status::Ok);
    ASSERT_EQ(hose.heldPoint(), last);
    const ReelResult r = reel(hose, HoseEnd::Start, 0.06, 0.0, 1.0);
    ASSERT_EQ(r.status, Status::Clamped) << r.message; // the held end leaves no room
    EXPECT_EQ(hose.heldPoint(), hose.pointCount() - 1);
}

namespace {

void report(const char* name, const Walk& walk)
{
    std::cout << "[ reel ] " << name << ": in " << walk.paidIn << " m, out " << walk.paidOut
              << " m in " << walk.frames << " frames; largest move " << walk.largestMoveOverPaid
              << " x |paid|; worst band " << walk.worstLength << ", bend " << walk.worstAngle
              << " rad; Newton steps " << walk.iterations << " (" << walk.mostIterations
              << " in the costliest frame)\n";
}

} // namespace

TEST(Reel, ABentFreeTailReelsInAndOutAtTheSpeedAsked)
{
    // From the outlet the hose turns down at its minimum bend radius, then sideways out of the
    // plane: reeled in, the bends beyond the outlet come in one after the other.
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.06, 0, 0), Vec3(0.06, -0.15, 0),
                                  Vec3(0.06, -0.15, 0.2), Vec3(0.25, -0.15, 0.2)},
                                 reelSpec());
    hose.attach(0, 1, Frame::identity());
    ASSERT_EQ(hose.measureViolation().status, Status::Ok);
    const int segments = hose.segmentCount();
    const double total0 = hose.restLengthTotal();
    const Walk walk = payOutAndBack(
        hose, 0.3, [](Hose& h, double l) { return reel(h, HoseEnd::Start, l, 0.0, 10.0); },
        startOutlet, -1, kReelMoveFactor);
    report("bent free tail", walk);
    EXPECT_EQ(walk.frames, 2 * 54);
    EXPECT_EQ(walk.framesValid, walk.frames);
    EXPECT_NEAR(walk.paidIn, 0.3, 1e-12);
    EXPECT_NEAR(walk.paidOut, 0.3, 1e-12);
    EXPECT_NEAR(hose.restLengthTotal(), total0, 1e-9);
    EXPECT_EQ(hose.segmentCount(), segments);
}

TEST(Reel, ABentSpanBetweenTwoFixedEndsReelsInAndOutAtTheSpeedAsked)
{
    // A U between two parts, 1.05 m of hose over 0.45 m: reeled in, the U gets shallower.
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.1, -0.3, 0),
                                  Vec3(0.35, -0.3, 0), Vec3(0.35, 0, 0), Vec3(0.45, 0, 0)},
                                 reelSpec());
    const int n = hose.pointCount() - 1;
    hose.attach(0, 1, Frame::identity());
    const int part = hose.attach(n - 1, n, Frame::identity());
    ASSERT_EQ(hose.measureViolation().status, Status::Ok);
    const int segments = hose.segmentCount();
    const Walk walk = payOutAndBack(
        hose, 0.3, [](Hose& h, double l) { return reel(h, HoseEnd::Start, l, 0.0, 10.0); },
        startOutlet, -1, kReelMoveFactor);
    report("bent span between two fixed ends", walk);
    EXPECT_EQ(walk.frames, 2 * 54);
    EXPECT_EQ(walk.framesValid, walk.frames);
    EXPECT_NEAR(walk.paidIn, 0.3, 1e-12);
    EXPECT_NEAR(walk.paidOut, 0.3, 1e-12);
    EXPECT_EQ(hose.segmentCount(), segments);
    EXPECT_LE(hose.attachmentGap(part), 1e-9);
}

TEST(Reel, ABentHoseThroughAClipOutletReelsInAndOutAtTheSpeedAsked)
{
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.25, 0, 0), Vec3(0.25, -0.2, 0),
                                  Vec3(0.25, -0.2, 0.25), Vec3(0.45, -0.2, 0.25)},
                                 reelSpec());
    const int clip = hose.addClip(0.2, Frame::identity());
    const int clipLast = hose.attachments().back().last;
    std::vector<Vec3> drum;
    for (int i = 0; i <= clipLast; ++i)
        drum.push_back(hose.point(i));
    const int segments = hose.segmentCount();
    auto clipOutlet = [clip](const Hose& h) {
        for (const Hose::Attachment& a : h.attachments())
            if (a.id == clip) return std::pair<int, int>{a.last, +1};
        return std::pair<int, int>{-1, +1};
    };
    const Walk walk = payOutAndBack(
        hose, 0.3,
        [clip](Hose& h, double l) { return reelThroughClip(h, clip, HoseEnd::Start, l, 0, 10); },
        clipOutlet, -1, kReelMoveFactor);
    report("bent hose through a clip outlet", walk);
    EXPECT_EQ(walk.frames, 2 * 54);
    EXPECT_EQ(walk.framesValid, walk.frames);
    EXPECT_NEAR(walk.paidIn, 0.3, 1e-12);
    EXPECT_NEAR(walk.paidOut, 0.3, 1e-12);
    EXPECT_EQ(hose.segmentCount(), segments);
    for (int i = 0; i <= clipLast; ++i)
        EXPECT_EQ(hose.point(i), drum[static_cast<size_t>(i)]) << i;
}

TEST(Reel, ABentFreeTailReeledInSlowlyKeepsTheSpeedAsked)
{
    // A tenth of the speed: the reel segment gets shorter than a frame's length before it merges.
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.06, 0, 0), Vec3(0.06, -0.15, 0),
                                  Vec3(0.06, -0.15, 0.2), Vec3(0.25, -0.15, 0.2)},
                                 reelSpec());
    hose.attach(0, 1, Frame::identity());
    const double total0 = hose.restLengthTotal();
    const double ask = 0.1 * kSpeed * kFrame;
    int merges = 0;
    double worst = 0.0;
    for (int frame = 0; frame < 540; ++frame) {
        const ReelResult r = reel(hose, HoseEnd::Start, -ask, 0.0, 10.0);
        ASSERT_EQ(r.status, Status::Ok) << "frame " << frame << ": " << r.message;
        EXPECT_NEAR(r.paid, -ask, 1e-15);
        EXPECT_LE(r.largestMove, kReelMoveFactor * ask * (1.0 + 1e-9));
        worst = std::max(worst, r.largestMove / ask);
        merges += r.segmentsRemoved;
        const Violation v = violation(hose);
        ASSERT_LE(std::max(v.length, v.angle), 1e-9) << "frame " << frame;
    }
    EXPECT_NEAR(hose.restLengthTotal(), total0 - 0.3, 1e-9);
    EXPECT_GE(merges, 14);
    std::cout << "[ reel ] bent free tail at 0.05 m/s: 0.3 m in, " << merges
              << " merges, largest move " << worst << " x |paid|\n";
}
