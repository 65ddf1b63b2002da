// The runtime's per-frame budget (HoseRuntime::setBudget): every hose runs under
// UpdateBudget::realtime() from load; a node move whose work exceeds the budget leaves the hose
// valid and pending, and update() goes on with it frame by frame until the attachment is met.
#include "export_test_support.h"

#include <chaintube/export/runtime.h>

namespace chaintube::exporting::testing {
namespace {

/// Every segment within its band and every joint within its limit (1e-9).
void expectValid(const Hose& hose, int frame)
{
    const UpdateResult v = hose.measureViolation();
    EXPECT_LE(v.lengthViolation, 1e-9) << "frame " << frame;
    EXPECT_LE(v.angleViolation, 1e-9) << "frame " << frame;
}

/// The largest attachmentGap() of a hose's attachments.
double largestGap(const Hose& hose)
{
    double gap = 0.0;
    for (const Hose::Attachment& a : hose.attachments())
        gap = std::max(gap, hose.attachmentGap(a.id));
    return gap;
}

TEST(HoseRuntimeBudget, ANodeJumpBeyondTheBudgetIsMetOverTheNextUpdatesEveryFrameValid)
{
    TemporaryFolder folder;
    const fs::path output = folder / "rig.glb";
    exportProjectFile(samplesDir() / "test-rig.ctproj", output, roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(output);
    EXPECT_EQ(runtime.budget().newtonSteps, UpdateBudget::kRealtimeNewtonSteps);
    for (int h = 0; h < runtime.hoseCount(); ++h)
        EXPECT_EQ(runtime.hose(h).budget().newtonSteps, UpdateBudget::kRealtimeNewtonSteps);
    EXPECT_THROW(runtime.setBudget(UpdateBudget{-1}), InvalidArgument);
    EXPECT_EQ(runtime.budget().newtonSteps, UpdateBudget::kRealtimeNewtonSteps);
    EXPECT_FALSE(runtime.pending(-1));
    EXPECT_EQ(runtime.remaining(runtime.hoseCount()), 0.0);

    rig::HoseRuntime unbounded = rig::HoseRuntime::load(output);
    unbounded.setBudget(UpdateBudget{});
    constexpr int kSteps = 6; // small, so that the jump below cannot be met in one update
    runtime.setBudget(UpdateBudget{kSteps});
    const int hose = runtime.findHose("right-return");
    const int valve = runtime.findNode("valve");
    ASSERT_GE(hose, 0);
    ASSERT_GE(valve, 0);
    // The valve jumps 6 cm up and turns by 0.3 rad in one frame.
    rig::NodeTransform moved = runtime.node(valve).local;
    moved.translation += Vec3(0.0, 0.06, 0.0);
    moved.rotation = (Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ())) * moved.rotation).normalized();
    const std::vector<rig::HoseUpdate> jumped = runtime.setNodeTransform(valve, moved);
    static_cast<void>(unbounded.setNodeTransform(valve, moved));
    bool jumpPending = false;
    for (const rig::HoseUpdate& update : jumped) {
        EXPECT_LE(update.result.iterations, kSteps) << "hose " << update.hose;
        expectValid(runtime.hose(update.hose), 0);
        EXPECT_EQ(update.result.pending, runtime.pending(update.hose));
        if (update.hose == hose) jumpPending = update.result.pending;
    }
    ASSERT_TRUE(jumpPending) << "the jump takes more than " << kSteps << " Newton steps";
    EXPECT_GT(runtime.remaining(hose), 0.0);
    EXPECT_NEAR(runtime.remaining(hose), largestGap(runtime.hose(hose)), 1e-12);
    // Held there: each update() goes on, within the budget, every frame valid.
    int frames = 1;
    for (; frames <= 100 && runtime.pending(hose); ++frames) {
        runtime.update();
        const UpdateResult& frame = runtime.frameResult(hose);
        EXPECT_LE(frame.iterations, kSteps) << "frame " << frames;
        EXPECT_EQ(frame.pending, runtime.pending(hose)) << "frame " << frames;
        expectValid(runtime.hose(hose), frames);
    }
    EXPECT_LE(frames, 100);
    EXPECT_FALSE(runtime.pending(hose));
    EXPECT_EQ(runtime.remaining(hose), 0.0);
    EXPECT_LE(largestGap(runtime.hose(hose)), 1e-9);
    // The unbounded runtime met it in the jump's frame; both hold the hose's ends alike.
    EXPECT_FALSE(unbounded.pending(hose));
    const Hose& a = runtime.hose(hose);
    const Hose& b = unbounded.hose(hose);
    for (const Hose::Attachment& attachment : a.attachments())
        for (int i = attachment.first; i <= attachment.last; ++i)
            EXPECT_LE((a.point(i) - b.point(i)).norm(), 1e-9) << i;
    // Lifted, the budget no longer bounds a move: a jump back is met in its frame.
    runtime.setBudget(UpdateBudget{});
    for (const rig::HoseUpdate& update :
         runtime.setNodeTransform(valve, unbounded.node(valve).local)) {
        EXPECT_FALSE(update.result.pending);
        EXPECT_FALSE(runtime.pending(update.hose));
    }
}

} // namespace
} // namespace chaintube::exporting::testing
