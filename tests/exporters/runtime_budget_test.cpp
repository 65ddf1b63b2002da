// The runtime's per-frame budget (HoseRuntime::setBudget): every hose runs under
// UpdateBudget::realtime() from load; a node move whose work exceeds the budget leaves the hose
// valid and pending, and update() goes on with it frame by frame until the attachment is met.
#include "export_test_support.h"

#include <algorithm>
#include <chaintube/export/runtime.h>
#include <cstdio>
#include <numbers>

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

/// The work (Newton steps) of the update() calls of one hose, frame by frame.
struct FrameWork
{
    std::vector<int> steps;
    int worst() const { return steps.empty() ? 0 : *std::max_element(steps.begin(), steps.end()); }
    int median() const
    {
        if (steps.empty()) return 0;
        std::vector<int> sorted = steps;
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        return sorted[sorted.size() / 2];
    }
};

/// update() until `hose` is no longer pending (at most `limit` frames), each frame's work
/// recorded, each frame's segments in their bands. Returns the frames it took (limit + 1: still
/// pending).
int updateUntilNotPending(rig::HoseRuntime& runtime, int hose, int limit, FrameWork& work)
{
    for (int frame = 1; frame <= limit; ++frame) {
        runtime.update();
        work.steps.push_back(runtime.frameResult(hose).iterations);
        EXPECT_LE(runtime.frameResult(hose).lengthViolation, 1e-9) << "frame " << frame;
        EXPECT_LE(runtime.hose(hose).measureViolation().lengthViolation, 1e-9) << "frame " << frame;
        if (!runtime.pending(hose)) return frame;
    }
    return limit + 1;
}

TEST(HoseRuntimeBudget, StalledMovesAndGravityNeverTakeMoreThanTheBudgetInAFrame)
{
    // What no budgeted try advances gives way or rests in the library: no update() finishes
    // it without the budget, so every frame's work (Newton steps, counted) stays within it.
    const int budget = UpdateBudget::kRealtimeNewtonSteps;
    TemporaryFolder folder;
    {
        // The valve turned by 2.5 rad about its vertical axis and lifted: right-return's end
        // attachment goes where its bends must give way (or beyond reach).
        const fs::path output = folder / "rig.glb";
        exportProjectFile(samplesDir() / "test-rig.ctproj", output, roots());
        rig::HoseRuntime runtime = rig::HoseRuntime::load(output);
        rig::HoseRuntime unbounded = rig::HoseRuntime::load(output);
        unbounded.setBudget(UpdateBudget{});
        const int valve = runtime.findNode("valve");
        ASSERT_GE(valve, 0);
        const rig::NodeTransform home = runtime.node(valve).local;
        const int bracket = runtime.findNode("bracket_right");
        ASSERT_GE(bracket, 0);
        // Towards bracket_right, where right-return's other end is (world = local here: the
        // nodes hang from the scene's root).
        const Vec3 toBracket = runtime.node(bracket).local.translation - home.translation;
        for (const double turn : {1.5, 2.5, 3.1}) {
            rig::NodeTransform moved = home;
            moved.rotation =
                (Quat(Eigen::AngleAxisd(turn, Vec3::UnitY())) * moved.rotation).normalized();
            moved.translation += 0.6 * toBracket;
            std::vector<int> moves(static_cast<size_t>(runtime.hoseCount()), 0);
            for (const rig::HoseUpdate& update : runtime.setNodeTransform(valve, moved)) {
                EXPECT_LE(update.result.iterations, budget) << "hose " << update.hose;
                moves[static_cast<size_t>(update.hose)] = update.result.iterations;
            }
            int unboundedMost = 0;
            for (const rig::HoseUpdate& update : unbounded.setNodeTransform(valve, moved))
                unboundedMost = std::max(unboundedMost, update.result.iterations);
            for (int h = 0; h < runtime.hoseCount(); ++h) {
                FrameWork work;
                const int frames = updateUntilNotPending(runtime, h, 300, work);
                EXPECT_LE(frames, 300) << "hose " << h << ", turn " << turn;
                EXPECT_LE(work.worst(), budget) << "hose " << h << ", turn " << turn;
                std::printf("[ figures ] valve turned %.1f rad, hose %d: the move %d steps "
                            "(unbounded %d), then %d frames pending, work a frame worst %d "
                            "median %d, %s, angle %.3g rad, gap %.3g m\n",
                            turn, h, moves[static_cast<size_t>(h)], unboundedMost, frames,
                            work.worst(), work.median(), toString(runtime.frameResult(h).status),
                            runtime.hose(h).measureViolation().angleViolation,
                            largestGap(runtime.hose(h)));
            }
        }
    }
    {
        // rig-options' bracket-loop with gravity on, bracket_right carried round a loop in a
        // second and held: every frame's gravity step and pending work within the budget, and
        // the loop stops being pending once the bracket is held still.
        const fs::path glb = exportLoopWithGravity(folder);
        rig::HoseRuntime runtime = rig::HoseRuntime::load(glb);
        const int loop = runtime.findHose("bracket-loop");
        const int bracket = runtime.findNode("bracket_right");
        ASSERT_GE(loop, 0);
        ASSERT_GE(bracket, 0);
        const rig::NodeTransform home = runtime.node(bracket).local;
        FrameWork walk;
        for (int k = 1; k <= 90; ++k) {
            const double phase = 2.0 * std::numbers::pi * k / 90.0;
            rig::NodeTransform moved = home;
            moved.translation += Vec3(-0.04 * std::sin(phase), 0.03 * (1.0 - std::cos(phase)),
                                      0.03 * std::sin(phase) * std::cos(phase));
            int move = 0;
            for (const rig::HoseUpdate& update : runtime.setNodeTransform(bracket, moved))
                if (update.hose == loop) move = update.result.iterations;
            EXPECT_LE(move, budget) << "frame " << k;
            runtime.update();
            walk.steps.push_back(runtime.frameResult(loop).iterations - move);
            EXPECT_LE(runtime.hose(loop).measureViolation().lengthViolation, 1e-9) << k;
        }
        EXPECT_LE(walk.worst(), budget);
        FrameWork held;
        const int frames = updateUntilNotPending(runtime, loop, 600, held);
        EXPECT_LE(frames, 600) << "bracket-loop still pending";
        EXPECT_LE(held.worst(), budget);
        std::printf("[ figures ] bracket-loop with gravity: update() work a frame on the walk "
                    "worst %d median %d; held, %d frames to no longer pending (worst %d, "
                    "median %d)\n",
                    walk.worst(), walk.median(), frames, held.worst(), held.median());
    }
}

} // namespace
} // namespace chaintube::exporting::testing
