// Cutting a hose in two at an axis point.
#include "test_util.h"

using namespace chaintube;
using namespace chaintube::test;

namespace {

HoseSpec cutSpec()
{
    HoseSpec spec;
    spec.segmentCount = 30;
    spec.material.expansionCoefficient = 0.05;
    spec.material.bendLimit = BendLimit::minBendRadius(0.05);
    return spec;
}

} // namespace

TEST(CutHose, BothPiecesKeepTheirPointsRestLengthsAndAttachmentsAndEndFreeAtTheCut)
{
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.4, 0.2, 0), Vec3(0.8, 0, 0)}, cutSpec());
    const int n = hose.pointCount() - 1;
    const int a = hose.attach(0, 1, Frame::identity());
    const int b = hose.attach(n - 1, n, translated(Vec3(0.8, 0, 0)));
    const CutHose cut = cutHose(hose, 12);
    ASSERT_EQ(cut.before.pointCount(), 13);
    ASSERT_EQ(cut.after.pointCount(), n - 12 + 1);
    for (int i = 0; i <= 12; ++i)
        EXPECT_EQ(cut.before.point(i), hose.point(i));
    for (int i = 12; i <= n; ++i)
        EXPECT_EQ(cut.after.point(i - 12), hose.point(i));
    EXPECT_NEAR(cut.before.restLengthTotal() + cut.after.restLengthTotal(), hose.restLengthTotal(),
                1e-15);
    for (int s = 0; s < n; ++s)
        EXPECT_EQ(s < 12 ? cut.before.restLength(s) : cut.after.restLength(s - 12),
                  hose.restLength(s));
    EXPECT_EQ(cut.before.material().bendLimit.value, 0.05);
    // Each attachment on its piece, the cut ends free.
    ASSERT_EQ(cut.attachments.size(), 2u);
    EXPECT_EQ(cut.attachments[0].piece, 0);
    EXPECT_EQ(cut.attachments[1].piece, 1);
    ASSERT_EQ(cut.before.attachments().size(), 1u);
    ASSERT_EQ(cut.after.attachments().size(), 1u);
    EXPECT_EQ(cut.before.attachments()[0].first, 0);
    EXPECT_EQ(cut.before.attachments()[0].last, 1);
    EXPECT_EQ(cut.after.attachments()[0].first, n - 13);
    EXPECT_EQ(cut.after.attachments()[0].last, n - 12);
    EXPECT_FALSE(cut.before.isFixed(12));
    EXPECT_FALSE(cut.after.isFixed(0));
    static_cast<void>(a);
    static_cast<void>(b);
    // The pieces go on as hoses of their own: the part moved, its piece follows, the free end
    // trails; the other piece is untouched.
    Hose after = cut.after;
    const UpdateResult moved =
        after.moveAttachment(cut.attachments[1].id, translated(Vec3(0.9, 0.1, 0)));
    EXPECT_EQ(moved.status, Status::Ok);
    EXPECT_CONSTRAINTS_HOLD(after, 1e-9);
    EXPECT_LE(after.attachmentGap(cut.attachments[1].id), 1e-9);
}

TEST(CutHose, AClipGoesWithItsPieceAtItsPlaceAlongIt)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, cutSpec());
    ClipOptions options;
    options.slideMin = 0.5;
    options.slideMax = 0.9;
    const int clip = hose.addClip(0.75, Frame::identity(), options);
    static_cast<void>(clip);
    const CutHose cut = cutHose(hose, 15); // at 0.5 m
    ASSERT_EQ(cut.after.attachments().size(), 1u);
    const Hose::Attachment& moved = cut.after.attachments()[0];
    EXPECT_TRUE(moved.isClip());
    EXPECT_NEAR(moved.slide, 0.25, 1e-12);
    EXPECT_NEAR(moved.slideMin, 0.0, 1e-12);
    EXPECT_NEAR(moved.slideMax, 0.4, 1e-12);
    EXPECT_TRUE(cut.before.attachments().empty());
}

TEST(CutHose, AnEndAPointOutOfRangeOrAHeldPointIsRefusedByName)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, cutSpec());
    hose.attach(10, 12, Frame::identity());
    hose.addClip(0.75, Frame::identity());
    for (const int point : {0, 30, -1, 31, 11, 22, 23}) {
        try {
            static_cast<void>(cutHose(hose, point));
            ADD_FAILURE() << "point " << point << " was cut";
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find("cut point"), std::string::npos) << e.what();
        }
    }
    EXPECT_NO_THROW(static_cast<void>(cutHose(hose, 15)));
}
