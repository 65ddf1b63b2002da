// Clips (Hose::addClip): the hose passes through the clip's centre along its axis and slides
// through it. Every test measures the hose itself: every segment in its band, every joint
// within its limit, the length of the axis conserved, the clip's centre on the hose.
#include "test_util.h"

#include <gtest/gtest.h>
#include <random>

namespace chaintube {
namespace {

using test::translated;
using test::violation;

/// 1 m, 50 segments, inextensible, minimum bend radius 0.1 m.
HoseSpec clipSpec()
{
    HoseSpec spec;
    spec.outerDiameter = 0.01;
    spec.segmentCount = 50;
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    return spec;
}

const Hose::Attachment& attachment(const Hose& hose, int id)
{
    for (const Hose::Attachment& a : hose.attachments())
        if (a.id == id) return a;
    throw std::runtime_error("no attachment " + std::to_string(id));
}

/// How far the clip's centre is from the hose's axis and how far the segment through it turns
/// from the clip's axis (radians), and the rest arc length from point 0 to the centre along
/// the hose (measured on the current shape, segment by segment).
struct Through
{
    double distance = 0.0;
    double turn = 0.0;
    double arcLength = 0.0;
};

Through through(const Hose& hose, int id)
{
    const Hose::Attachment& clip = attachment(hose, id);
    const Vec3 centre = clip.frame.apply(clip.clipCentre);
    const Vec3 axis = clip.frame.rotation * clip.clipAxis;
    const Vec3 a = hose.point(clip.first), b = hose.point(clip.last);
    const Vec3 d = (b - a).normalized();
    Through t;
    t.distance = ((centre - a) - (centre - a).dot(d) * d).norm();
    t.turn = std::atan2(d.cross(axis).norm(), d.dot(axis));
    for (int s = 0; s < clip.first; ++s)
        t.arcLength += (hose.point(s + 1) - hose.point(s)).norm();
    t.arcLength += (centre - a).dot(d);
    return t;
}

TEST(Clip, AddedAtAPlaceHoldsTheHoseThereWithoutMovingIt)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, clipSpec());
    const std::vector<Vec3> before = hose.points();
    const int id = hose.addClip(0.51, Frame::identity());
    EXPECT_EQ(hose.points(), before);
    const Hose::Attachment& clip = attachment(hose, id);
    EXPECT_EQ(clip.hold, Hold::Sliding);
    EXPECT_EQ(clip.first, 25);
    EXPECT_EQ(clip.last, 26);
    EXPECT_NEAR((clip.frame.apply(clip.clipCentre) - Vec3(0.51, 0, 0)).norm(), 0.0, 1e-15);
    EXPECT_NEAR((clip.clipAxis - Vec3::UnitX()).norm(), 0.0, 1e-15);
    EXPECT_DOUBLE_EQ(clip.slide, 0.51);
    EXPECT_TRUE(hose.isFixed(25));
    EXPECT_TRUE(hose.isFixed(26));
    EXPECT_NEAR(hose.attachmentGap(id), 0.0, 1e-15);
    EXPECT_TRUE(hose.detach(id));
    EXPECT_FALSE(hose.isFixed(25));
}

TEST(Clip, BadPlacesAndOptionsAreRejectedNamingTheField)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, clipSpec());
    hose.attach(0, 1, Frame::identity());
    auto message = [&](double place, ClipOptions options) {
        try {
            (void)hose.addClip(place, Frame::identity(), options);
        } catch (const InvalidArgument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(message(1.5, {}).find("clip place: expected a rest arc length in 0 … 1"),
              std::string::npos);
    EXPECT_NE(message(std::nan(""), {}).find("clip place"), std::string::npos);
    EXPECT_NE(message(0.01, {}).find("already fixed"), std::string::npos);
    EXPECT_NE(message(0.5, {Hold::Fixed}).find("clip hold"), std::string::npos);
    EXPECT_NE(message(0.5, {Hold::Sliding, 0.6, 0.4}).find("clip end stops"), std::string::npos);
    EXPECT_NE(message(0.5, {Hold::Sliding, 0.6, 0.9}).find("0.6"), std::string::npos);
    EXPECT_EQ(hose.attachments().size(), 1u); // nothing was added
}

/// A hose with slack near point 0 (a bump) and a straight run to a free end at x = 1 m,
/// 60 segments; point 0 attached.
Hose bumpHose(int& end)
{
    HoseSpec spec = clipSpec();
    spec.segmentCount = 60;
    Hose hose = Hose::alongRoute(
        {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.25, 0.15, 0), Vec3(0.4, 0, 0), Vec3(1.0, 0, 0)},
        spec);
    end = hose.attach(0, 1, Frame::identity());
    return hose;
}

/// The rest arc length at which the straight run of bumpHose passes x.
double placeAtX(const Hose& hose, double x)
{
    int s = 0;
    while (hose.point(s + 1).x() < x || hose.point(s + 1).y() > 1e-9)
        ++s;
    double place = x - hose.point(s).x();
    for (int k = 0; k < s; ++k)
        place += hose.restLength(k);
    return place;
}

/// bumpHose with its far end fixed too and a sliding clip on the straight run at x = 0.6 m.
struct ClippedBetweenEnds
{
    Hose hose;
    int a = -1, b = -1, clip = -1;
    double length = 0.0; ///< of the axis as built
};

ClippedBetweenEnds clippedBetweenEnds()
{
    int a = -1;
    ClippedBetweenEnds c{bumpHose(a)};
    c.a = a;
    const int n = c.hose.pointCount() - 1;
    c.b = c.hose.attach(n - 1, n, Frame::identity());
    c.clip = c.hose.addClip(placeAtX(c.hose, 0.6), Frame::identity());
    c.length = c.hose.currentLength();
    return c;
}

/// Every constraint, both ends and the clip met, the length as built, the hose through the
/// clip's centre.
void expectHeldThroughTheClip(const ClippedBetweenEnds& c, const Hose& hose,
                              const std::string& when)
{
    EXPECT_LE(violation(hose).length, 1e-9) << when;
    EXPECT_LE(violation(hose).angle, 1e-9) << when;
    EXPECT_LE(hose.attachmentGap(c.a), 1e-9) << when;
    EXPECT_LE(hose.attachmentGap(c.b), 1e-9) << when;
    EXPECT_LE(hose.attachmentGap(c.clip), 1e-9) << when;
    EXPECT_NEAR(hose.currentLength(), c.length, 1e-9) << when;
    EXPECT_LE(through(hose, c.clip).distance, 1e-12) << when;
}

/// A fixed end pulled away from a clip: the hose slides through the clip from its free side.
TEST(Clip, AnEndPulledAwayDrawsTheHoseThroughTheClipFromTheFreeSide)
{
    int end = -1;
    Hose hose = bumpHose(end);
    ASSERT_TRUE(hose.measureViolation().ok());
    const int clip = hose.addClip(placeAtX(hose, 0.6), Frame::identity());
    const double length = hose.currentLength();
    double lastSlide = attachment(hose, clip).slide;
    for (int k = 1; k <= 20; ++k) {
        const UpdateResult r = hose.moveAttachment(end, translated(Vec3(-0.01 * k, 0, 0)));
        ASSERT_EQ(r.status, Status::Ok) << "step " << k;
        const test::Violation v = violation(hose);
        EXPECT_LE(v.length, 1e-9) << "step " << k;
        EXPECT_LE(v.angle, 1e-9) << "step " << k;
        EXPECT_LE(hose.attachmentGap(end), 1e-9);
        EXPECT_LE(hose.attachmentGap(clip), 1e-9);
        EXPECT_NEAR(hose.currentLength(), length, 1e-9) << "length conserved";
        const Through t = through(hose, clip);
        EXPECT_LE(t.distance, 1e-12);
        EXPECT_LE(t.turn, 1e-9);
        EXPECT_NEAR(t.arcLength, attachment(hose, clip).slide, 1e-9);
        EXPECT_GE(attachment(hose, clip).slide, lastSlide) << "slides one way only";
        lastSlide = attachment(hose, clip).slide;
    }
    // The end's second point is at x = −0.2 + one segment, 0.8 m − a segment from the clip's
    // centre: at least that much hose is on its side, within the 1 % margin the slide keeps.
    const double segment = hose.restLength(0);
    EXPECT_GE(lastSlide - segment, 0.8 - segment);
    EXPECT_LE(lastSlide - segment, (0.8 - segment) / 0.99 + segment);
    // The free end came nearer the clip by what went through it.
    EXPECT_LE((hose.point(60) - Vec3(0.6, 0, 0)).norm(), hose.restLengthTotal() - lastSlide + 1e-9);
}

/// Between two fixed ends the side pulled taut takes length from the side with slack.
TEST(Clip, BetweenTwoFixedEndsTheTautSideTakesTheOtherSidesSlack)
{
    ClippedBetweenEnds c = clippedBetweenEnds();
    Hose& hose = c.hose;
    const int a = c.a, b = c.b, clip = c.clip;
    const double length = c.length;
    const double slide0 = attachment(hose, clip).slide;
    for (int k = 1; k <= 5; ++k) {
        const UpdateResult r = hose.moveAttachment(b, translated(Vec3(0.01 * k, 0, 0)));
        ASSERT_EQ(r.status, Status::Ok) << "step " << k;
        EXPECT_LE(violation(hose).length, 1e-9);
        EXPECT_LE(violation(hose).angle, 1e-9);
        EXPECT_LE(hose.attachmentGap(a), 1e-9);
        EXPECT_LE(hose.attachmentGap(b), 1e-9);
        EXPECT_LE(hose.attachmentGap(clip), 1e-9);
        EXPECT_NEAR(hose.currentLength(), length, 1e-9);
        EXPECT_LE(through(hose, clip).distance, 1e-12);
    }
    // The far end moved 0.05 m from the clip: its side took about that much from the bump.
    const double fed = slide0 - attachment(hose, clip).slide;
    EXPECT_GE(fed, 0.05);
    EXPECT_LE(fed, 0.05 + 0.02);
    // Pulled on, the bump runs out (about 0.07 m of slack): the end is left short, reported.
    UpdateResult r;
    for (int k = 6; k <= 15; ++k) {
        r = hose.moveAttachment(b, translated(Vec3(0.01 * k, 0, 0)));
        EXPECT_LE(violation(hose).length, 1e-9);
        EXPECT_NEAR(hose.currentLength(), length, 1e-9);
    }
    EXPECT_EQ(r.status, Status::Infeasible);
    EXPECT_GT(hose.attachmentGap(b), 0.01);
    EXPECT_LE(hose.attachmentGap(a), 1e-9);
}

TEST(Clip, TheSlideStopsAtItsEndStopAndTheUpdateSaysSo)
{
    int end = -1;
    Hose hose = bumpHose(end);
    const double place = placeAtX(hose, 0.6);
    const int clip = hose.addClip(place, Frame::identity(), {Hold::Sliding, 0.0, place + 0.05});
    UpdateResult r;
    for (int k = 1; k <= 20; ++k)
        r = hose.moveAttachment(end, translated(Vec3(-0.01 * k, 0, 0)));
    EXPECT_EQ(r.status, Status::Infeasible);
    EXPECT_DOUBLE_EQ(attachment(hose, clip).slide, place + 0.05);
    EXPECT_GT(hose.attachmentGap(end), 0.01);
    EXPECT_LE(hose.attachmentGap(clip), 1e-9);
    EXPECT_LE(violation(hose).length, 1e-9);
}

TEST(Clip, AFreeEndGrabbedAndPulledSlidesTheHoseThroughTheClip)
{
    int end = -1;
    Hose hose = bumpHose(end);
    const int clip = hose.addClip(placeAtX(hose, 0.6), Frame::identity());
    const double length = hose.currentLength();
    const double slide0 = attachment(hose, clip).slide;
    // The free end is 0.4 m past the clip with as much hose: pull it out 0.05 m more.
    const Vec3 target = hose.point(60) + Vec3(0.05, 0, 0);
    UpdateResult r;
    for (int k = 0; k < 10 && (k == 0 || r.status != Status::Ok); ++k)
        r = hose.grab(60, target);
    EXPECT_EQ(r.status, Status::Ok);
    EXPECT_LE(r.grabError, 1e-9);
    EXPECT_LT(attachment(hose, clip).slide, slide0 - 0.05);
    EXPECT_LE(violation(hose).length, 1e-9);
    EXPECT_LE(violation(hose).angle, 1e-9);
    EXPECT_LE(hose.attachmentGap(clip), 1e-9);
    EXPECT_LE(hose.attachmentGap(end), 1e-9);
    EXPECT_NEAR(hose.currentLength(), length, 1e-9);
}

/// The clip moved 8 cm along its own axis in one update, between two fixed ends: it slides
/// along the hose, which stays where it is (the side ahead of it left exactly taut is given
/// back the 1 % margin from the other side's slack).
TEST(Clip, AClipMovedFarAlongItsAxisSlidesAlongTheHoseWhichStays)
{
    ClippedBetweenEnds c = clippedBetweenEnds();
    const double slide0 = attachment(c.hose, c.clip).slide;
    EXPECT_EQ(c.hose.moveAttachment(c.clip, translated(Vec3(0.08, 0, 0))).status, Status::Ok);
    expectHeldThroughTheClip(c, c.hose, "moved along");
    // The 0.32 m to the far end keep 1 % more than their straight line.
    const double slid = attachment(c.hose, c.clip).slide - slide0;
    EXPECT_LE(slid, 0.08);
    EXPECT_GE(slid, 0.08 - 0.011 * 0.32);
}

/// The clip moved 8 cm across the hose in one update: from its slide as it was no shape is
/// found, so the move is made in two halves, as a drag would make it: the hose ends exactly
/// where two 4 cm moves leave it, every constraint held.
TEST(Clip, AClipMovedFarAcrossTheHoseInOneUpdateIsFollowedAsADrag)
{
    for (const Vec3& direction : {Vec3(0, 1, 0), Vec3(0, 0, 1)}) {
        ClippedBetweenEnds c = clippedBetweenEnds();
        Hose& jump = c.hose;
        Hose halves = jump;
        const UpdateResult r = jump.moveAttachment(c.clip, translated(0.08 * direction));
        EXPECT_EQ(r.status, Status::Ok);
        EXPECT_GT(r.movedPoints, 0);
        expectHeldThroughTheClip(c, jump, "moved across");
        for (const double d : {0.04, 0.08})
            ASSERT_EQ(halves.moveAttachment(c.clip, translated(d * direction)).status, Status::Ok);
        for (int i = 0; i < jump.pointCount(); ++i)
            EXPECT_EQ(jump.point(i), halves.point(i)) << "point " << i;
        EXPECT_EQ(attachment(jump, c.clip).slide, attachment(halves, c.clip).slide);
    }
}

/// A long random walk of the clip's part (±4 cm) and of the far end (±10 cm), 5 mm a frame
/// on each axis, moved together, of a hose with slack on both sides of the clip: every
/// constraint after every update, the clip met and on the hose, the length conserved.
/// `fixed`: the same walk with the clip's segment attached instead.
struct Walk
{
    std::vector<Vec3> points;
    int slides = 0;
    int notOk = 0;
    int maxIterations = 0;
};

Walk randomWalk(int frames, bool fixed)
{
    HoseSpec spec = clipSpec();
    spec.segmentCount = 60;
    Hose hose =
        Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.22, 0.15, 0), Vec3(0.34, 0, 0),
                          Vec3(0.66, 0, 0), Vec3(0.78, -0.15, 0), Vec3(0.9, 0, 0), Vec3(1.0, 0, 0)},
                         spec);
    EXPECT_TRUE(hose.settle().ok());
    const int n = hose.pointCount() - 1;
    hose.attach(0, 1, Frame::identity());
    const int b = hose.attach(n - 1, n, Frame::identity());
    const int clip = fixed ? hose.attach(30, 31, Frame::identity())
                           : hose.addClip(0.5 * hose.restLengthTotal(), Frame::identity());
    Vec3 clipAt = Vec3::Zero(), endAt = Vec3::Zero();
    std::mt19937 random(7);
    std::uniform_real_distribution<double> step(-0.005, 0.005);
    const double length = hose.currentLength();
    Walk walk;
    double slide = attachment(hose, clip).slide;
    for (int f = 0; f < frames; ++f) {
        clipAt += Vec3(step(random), step(random), step(random));
        clipAt = clipAt.cwiseMax(Vec3::Constant(-0.04)).cwiseMin(Vec3::Constant(0.04));
        endAt += Vec3(step(random), step(random), step(random));
        endAt = endAt.cwiseMax(Vec3::Constant(-0.1)).cwiseMin(Vec3::Constant(0.1));
        const UpdateResult r =
            hose.moveAttachments({clip, b}, {translated(clipAt), translated(endAt)});
        walk.notOk += r.status != Status::Ok;
        walk.maxIterations = std::max(walk.maxIterations, r.iterations);
        walk.slides += attachment(hose, clip).slide != slide;
        slide = attachment(hose, clip).slide;
        const test::Violation v = violation(hose);
        EXPECT_LE(v.length, 1e-9) << "frame " << f;
        if (r.status == Status::Ok) {
            EXPECT_LE(v.angle, 1e-9) << "frame " << f;
            EXPECT_LE(hose.attachmentGap(clip), 1e-9) << "frame " << f;
            EXPECT_LE(hose.attachmentGap(b), 1e-9) << "frame " << f;
            if (!fixed) {
                EXPECT_LE(through(hose, clip).distance, 1e-9) << "frame " << f;
            }
        }
        EXPECT_NEAR(hose.currentLength(), length, 1e-9) << "frame " << f;
        EXPECT_TRUE(test::allFinite(hose));
    }
    walk.points = hose.points();
    return walk;
}

TEST(Clip, ARandomWalkOfTheClipAndAnEndKeepsEveryConstraintAndIsDeterministic)
{
    const Walk first = randomWalk(2000, false);
    const Walk second = randomWalk(2000, false);
    EXPECT_EQ(first.points, second.points);
    EXPECT_GT(first.slides, 100) << "the walk makes the hose slide";
    // Fixed at the clip's segment the same walk leaves the far end short where the hose
    // cannot slide; through the clip nearly every update is met.
    const Walk fixed = randomWalk(2000, true);
    EXPECT_GT(fixed.notOk, 500);
    EXPECT_LE(first.notOk, 20);
    // The attachment move's budget with clips (lib/README.md): three attempts of
    // 2 × (2 × 12 per span + 4 + 8), two spans.
    EXPECT_LE(first.maxIterations, 3 * 2 * (2 * 12 * 2 + 4 + 8));
    std::cout << "through the clip: " << first.slides << " slides, " << first.notOk
              << " updates not Ok of 2000, at most " << first.maxIterations
              << " Newton steps an update; fixed there: " << fixed.notOk << " not Ok, at most "
              << fixed.maxIterations << "\n";
}

} // namespace
} // namespace chaintube
