// The runtime's sockets: a hose end plugged (plug()) or released in a socket's capture (release())
// eases into the socket over a few frames, each in the stretch band, and is held there; unplug()
// lets it go; a socket holds one end; bad input is refused and changes nothing.
#include "export_test_support.h"

#include <chaintube/export/runtime.h>
#include <cmath>
#include <iostream>

namespace chaintube::exporting::testing {
namespace {

// Updates of 1/90 s (update()) that a plugged end takes to ease in: kSnapSeconds.
constexpr int kEasingUpdates = 5;

/// The test rig (no gravity; left-feed from bracket_left to the valve's inlet, its last end
/// tagged camlock-19; sockets valve-outlet and plate-port, both camlock-19), exported to
/// `folder`/rig.glb and loaded. With `plugRightReturn`, right-return's ends are tagged
/// camlock-19 too.
rig::HoseRuntime loadSocketRig(const TemporaryFolder& folder, bool plugRightReturn = false)
{
    const fs::path file = samplesDir() / "test-rig.ctproj";
    formats::Project project = loadWithRoots(file);
    if (plugRightReturn)
        for (formats::HoseDefinition& hose : project.hoses)
            if (hose.id == "right-return") hose.plugs = {"camlock-19", "camlock-19"};
    const fs::path output = folder / "rig.glb";
    exportProject(project, file, output, roots());
    return rig::HoseRuntime::load(output);
}

/// Every segment of the hose is within its stretch band (1e-9 m of rounding).
bool inBand(const Hose& hose)
{
    for (int s = 0; s + 1 < hose.pointCount(); ++s) {
        const double length = (hose.point(s + 1) - hose.point(s)).norm();
        if (length < hose.minLength(s) - 1e-9 || length > hose.maxLength(s) + 1e-9) return false;
    }
    return true;
}

/// A hand carries axis point `point` of a hose to `target` in `frames` equal steps, one grab and
/// one update() a frame; every frame stays in the band.
void carry(rig::HoseRuntime& runtime, int hose, int point, const Vec3& target, int frames)
{
    const Vec3 from = runtime.hose(hose).point(point);
    for (int frame = 1; frame <= frames; ++frame) {
        const UpdateResult grabbed =
            runtime.grab(hose, point, from + (target - from) * (double(frame) / frames));
        ASSERT_NE(grabbed.status, Status::InvalidInput) << "frame " << frame;
        runtime.update();
        ASSERT_TRUE(inBand(runtime.hose(hose))) << "carrying, frame " << frame;
    }
}

/// The last end of a hose: its point and the way its end segment points out of the hose.
struct EndNow
{
    Vec3 tip;
    Vec3 outward;
};
EndNow lastEnd(const rig::HoseRuntime& runtime, int hose)
{
    const Hose& h = runtime.hose(hose);
    const int n = h.pointCount();
    return {h.point(n - 1), (h.point(n - 1) - h.point(n - 2)).normalized()};
}

TEST(HoseRuntimeSockets, AnEndReleasedInASocketsCaptureEasesInOverValidFramesAndIsHeld)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadSocketRig(folder);
    const int feed = runtime.findHose("left-feed");
    const int plate = runtime.findSocket("plate-port");
    ASSERT_GE(feed, 0);
    ASSERT_GE(plate, 0);
    const int n = runtime.hose(feed).pointCount();
    EXPECT_EQ(runtime.socketOccupant(plate).hose, -1);

    // Unplugged from the valve's inlet: no gravity, so the end stays where it is.
    const std::vector<Vec3> before = runtime.hose(feed).points();
    const rig::PlugResult unplugged = runtime.unplug(feed, 1);
    ASSERT_EQ(unplugged.status, Status::Ok);
    EXPECT_EQ(unplugged.socket, -1); // the export's attachment is in no socket
    EXPECT_EQ(unplugged.attachment, 1);
    runtime.update();
    EXPECT_EQ(runtime.hose(feed).points(), before);

    // Carried 20 cm above the plate port and 6 cm beyond it (seen from the bracket), then down
    // to 1 cm above it, 5 mm aside: within its capture (3 cm, 0.5 rad).
    const rig::HoseRuntime::SocketPose port = runtime.socket(plate);
    Vec3 beyond = port.position - runtime.hose(feed).point(0);
    beyond.y() = 0.0;
    beyond.normalize();
    carry(runtime, feed, n - 1, port.position + 0.2 * port.axis + 0.06 * beyond, 20);
    carry(runtime, feed, n - 1, port.position + 0.01 * port.axis + Vec3(0.005, 0.0, 0.0), 10);
    const EndNow atRelease = lastEnd(runtime, feed);
    const double distance = (atRelease.tip - port.position).norm();
    const double angle = std::acos(atRelease.outward.dot(-port.axis));
    ASSERT_LT(distance, port.description->captureRadius);
    ASSERT_LT(angle, port.description->captureAngle);

    const rig::PlugResult snapped = runtime.release(feed);
    ASSERT_EQ(snapped.status, Status::Ok);
    EXPECT_EQ(snapped.socket, plate);
    EXPECT_EQ(snapped.end, 1);
    EXPECT_EQ(snapped.attachment, 2);
    EXPECT_EQ(snapped.easingSeconds, rig::HoseRuntime::kSnapSeconds);
    const rig::SocketOccupant occupant = runtime.socketOccupant(plate);
    EXPECT_EQ(occupant.hose, feed);
    EXPECT_EQ(occupant.end, 1);
    EXPECT_EQ(occupant.attachment, 2);
    EXPECT_EQ(runtime.attachment(feed, 2).socket, plate);
    EXPECT_EQ(runtime.hose(feed).heldPoint(), -1);
    // The end's two points are fixed now: not grabbable.
    EXPECT_EQ(runtime.grabbablePoints(feed).back(), n - 3);
    // It has not moved yet: it eases in, each frame in the band.
    EXPECT_LT((runtime.hose(feed).point(n - 1) - atRelease.tip).norm(), 1e-9);
    double largestStep = 0.0;
    for (int frame = 0; frame < kEasingUpdates; ++frame) {
        const Vec3 was = runtime.hose(feed).point(n - 1);
        runtime.update();
        const UpdateResult& result = runtime.frameResult(feed);
        EXPECT_EQ(result.status, Status::Ok) << "easing, frame " << frame;
        EXPECT_LE(result.lengthViolation, 1e-9) << "easing, frame " << frame;
        EXPECT_TRUE(inBand(runtime.hose(feed))) << "easing, frame " << frame;
        const double step = (runtime.hose(feed).point(n - 1) - was).norm();
        EXPECT_GT(step, 0.0) << "easing, frame " << frame;
        largestStep = std::max(largestStep, step);
    }
    EXPECT_EQ(runtime.attachment(feed, 2).easingSeconds, 0.0);
    const EndNow seated = lastEnd(runtime, feed);
    EXPECT_LT((seated.tip - port.position).norm(), 1e-9);
    EXPECT_GT(seated.outward.dot(-port.axis), 1.0 - 1e-9);
    // No easing frame moves the end more than an even share of the way, with a margin.
    EXPECT_LE(largestStep, 1.5 * distance / kEasingUpdates + 1e-9);

    // Held by the socket: the plate moves and the end goes with it.
    const int plateNode = port.description->node;
    rig::NodeTransform moved = runtime.node(plateNode).local;
    for (int frame = 0; frame < 3; ++frame) {
        moved.translation.x() -= 0.01;
        (void)runtime.setNodeTransform(plateNode, moved);
        runtime.update();
        EXPECT_LT((lastEnd(runtime, feed).tip - runtime.socket(plate).position).norm(), 1e-9);
        EXPECT_TRUE(inBand(runtime.hose(feed))) << "plate moved, frame " << frame;
    }
    std::cout << "[ socket ] left-feed released " << distance << " m and " << angle
              << " rad from plate-port: seated in " << kEasingUpdates << " frames, largest step "
              << largestStep << " m\n";

    // Unplugged: the socket is free again and the end is grabbable.
    const rig::PlugResult out = runtime.unplug(feed, 1);
    EXPECT_EQ(out.status, Status::Ok);
    EXPECT_EQ(out.socket, plate);
    EXPECT_EQ(out.attachment, 2);
    EXPECT_EQ(runtime.socketOccupant(plate).hose, -1);
    EXPECT_EQ(runtime.grabbablePoints(feed).back(), n - 1);
}

TEST(HoseRuntimeSockets, APlugEasesInAtTheSamePaceAt45To120Hz)
{
    // The end released in plate-port's capture as above, then updates of 1/rate s: after t
    // seconds the end is t / kSnapSeconds of the way (in a straight line: the socket does not
    // move), seated once kSnapSeconds have passed, whatever the rate.
    const double snap = rig::HoseRuntime::kSnapSeconds;
    for (double rate : {45.0, 72.0, 90.0, 120.0}) {
        TemporaryFolder folder;
        rig::HoseRuntime runtime = loadSocketRig(folder);
        const int feed = runtime.findHose("left-feed");
        const int plate = runtime.findSocket("plate-port");
        ASSERT_GE(feed, 0);
        ASSERT_GE(plate, 0);
        const int n = runtime.hose(feed).pointCount();
        ASSERT_EQ(runtime.unplug(feed, 1).status, Status::Ok);
        runtime.update();
        const rig::HoseRuntime::SocketPose port = runtime.socket(plate);
        Vec3 beyond = port.position - runtime.hose(feed).point(0);
        beyond.y() = 0.0;
        beyond.normalize();
        carry(runtime, feed, n - 1, port.position + 0.2 * port.axis + 0.06 * beyond, 20);
        carry(runtime, feed, n - 1, port.position + 0.01 * port.axis + Vec3(0.005, 0.0, 0.0), 10);
        const Vec3 start = lastEnd(runtime, feed).tip;
        const rig::PlugResult snapped = runtime.release(feed);
        ASSERT_EQ(snapped.socket, plate) << rate << " Hz";
        EXPECT_EQ(snapped.easingSeconds, snap);
        const double frame = 1.0 / rate;
        double now = 0.0;
        int updates = 0;
        while (runtime.attachment(feed, snapped.attachment).easingSeconds > 0.0 && updates < 20) {
            runtime.update(frame);
            now += frame;
            ++updates;
            const double share = std::min(1.0, now / snap);
            const Vec3 expected = start + share * (port.position - start);
            EXPECT_LT((lastEnd(runtime, feed).tip - expected).norm(), 1e-6)
                << rate << " Hz, update " << updates;
            EXPECT_EQ(runtime.frameResult(feed).status, Status::Ok)
                << rate << " Hz, update " << updates;
            EXPECT_TRUE(inBand(runtime.hose(feed))) << rate << " Hz, update " << updates;
        }
        EXPECT_EQ(updates, static_cast<int>(std::ceil(snap * rate - 1e-9))) << rate << " Hz";
        const EndNow seated = lastEnd(runtime, feed);
        EXPECT_LT((seated.tip - port.position).norm(), 1e-9) << rate << " Hz";
        EXPECT_GT(seated.outward.dot(-port.axis), 1.0 - 1e-9) << rate << " Hz";
        std::cout << "[ socket ] at " << rate << " Hz left-feed seated in " << updates
                  << " updates\n";
    }
}

TEST(HoseRuntimeSockets, AnEndReleasedOutsideTheCaptureRadiusOrAngleStaysFree)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadSocketRig(folder);
    const int feed = runtime.findHose("left-feed");
    const int plate = runtime.findSocket("plate-port");
    const int n = runtime.hose(feed).pointCount();
    ASSERT_EQ(runtime.unplug(feed, 1).status, Status::Ok);
    const rig::HoseRuntime::SocketPose port = runtime.socket(plate);
    const double radius = port.description->captureRadius;

    // Above the port, 1.5 capture radii away along its axis: pointing in, too far.
    carry(runtime, feed, n - 1, port.position + 0.12 * port.axis, 20);
    carry(runtime, feed, n - 1, port.position + 1.5 * radius * port.axis, 10);
    EXPECT_GT((lastEnd(runtime, feed).tip - port.position).norm(), radius);
    rig::PlugResult released = runtime.release(feed);
    EXPECT_EQ(released.status, Status::Ok);
    EXPECT_EQ(released.socket, -1);
    EXPECT_EQ(runtime.socketOccupant(plate).hose, -1);
    EXPECT_EQ(runtime.attachmentCount(feed), 2);

    // Within the radius but coming in sideways: the end segment lies flat, beyond 0.5 rad.
    const Vec3 side = Vec3(0.0, 0.0, 1.0);
    carry(runtime, feed, n - 1, port.position + 0.01 * port.axis + 0.15 * side, 20);
    carry(runtime, feed, n - 1, port.position + 0.01 * port.axis + 0.005 * side, 10);
    const EndNow end = lastEnd(runtime, feed);
    EXPECT_LT((end.tip - port.position).norm(), radius);
    const double angle = std::acos(end.outward.dot(-port.axis));
    EXPECT_GT(angle, port.description->captureAngle);
    released = runtime.release(feed);
    EXPECT_EQ(released.status, Status::Ok);
    EXPECT_EQ(released.socket, -1);
    EXPECT_EQ(runtime.socketOccupant(plate).hose, -1);
    EXPECT_EQ(runtime.attachmentCount(feed), 2);
    std::cout << "[ socket ] not caught: 1.5 capture radii away; " << angle
              << " rad off the axis (capture 0.5 rad)\n";

    // Released where no hand holds it: nothing to snap.
    EXPECT_EQ(runtime.release(feed).socket, -1);
    EXPECT_EQ(runtime.release(-1).status, Status::InvalidInput);
    EXPECT_FALSE(runtime.release(runtime.hoseCount()));
}

TEST(HoseRuntimeSockets, BadPlugsAndUnplugsAreRefusedNamingWhyAndChangeNothing)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadSocketRig(folder, true);
    const int feed = runtime.findHose("left-feed");
    const int ret = runtime.findHose("right-return");
    const int plate = runtime.findSocket("plate-port");
    const int outlet = runtime.findSocket("valve-outlet");
    ASSERT_GE(ret, 0);
    ASSERT_EQ(runtime.unplug(feed, 1).status, Status::Ok);
    const rig::PlugResult plugged = runtime.plug(feed, 1, plate);
    ASSERT_EQ(plugged.status, Status::Ok);
    for (int frame = 0; frame < kEasingUpdates; ++frame)
        runtime.update();
    ASSERT_EQ(runtime.unplug(ret, 1).status, Status::Ok);
    runtime.update();

    std::string why;
    const auto refusedWith = [&](const auto& call, const std::string& expected) {
        std::vector<std::vector<Vec3>> points;
        std::vector<int> attachments;
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            points.push_back(runtime.hose(h).points());
            attachments.push_back(runtime.attachmentCount(h));
        }
        const rig::SocketOccupant plateHolds = runtime.socketOccupant(plate);
        const rig::SocketOccupant outletHolds = runtime.socketOccupant(outlet);
        why.clear();
        const rig::PlugResult result = call();
        EXPECT_EQ(result.status, Status::InvalidInput) << expected;
        EXPECT_FALSE(result) << expected;
        EXPECT_NE(why.find(expected), std::string::npos)
            << "expected \"" << expected << "\": " << why;
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            EXPECT_EQ(runtime.hose(h).points(), points[static_cast<size_t>(h)]) << expected;
            EXPECT_EQ(runtime.attachmentCount(h), attachments[static_cast<size_t>(h)]) << expected;
        }
        EXPECT_EQ(runtime.socketOccupant(plate).hose, plateHolds.hose) << expected;
        EXPECT_EQ(runtime.socketOccupant(outlet).hose, outletHolds.hose) << expected;
    };
    refusedWith([&] { return runtime.plug(ret, 1, plate, &why); },
                "socket \"plate-port\" holds end 1 of hose " + std::to_string(feed));
    refusedWith([&] { return runtime.plug(ret, 1, 7, &why); }, "socket 7 is out of range");
    refusedWith([&] { return runtime.plug(ret, 1, -1, &why); }, "socket -1 is out of range");
    refusedWith([&] { return runtime.plug(ret, 2, outlet, &why); }, "end 2");
    refusedWith([&] { return runtime.plug(99, 1, outlet, &why); }, "hose 99 is out of range");
    // left-feed's first end has no plug; right-return's first end is fixed to its bracket.
    refusedWith([&] { return runtime.plug(feed, 0, outlet, &why); },
                "end 0 of hose " + std::to_string(feed) + " (\"left-feed\") has no plug");
    refusedWith([&] { return runtime.plug(ret, 0, outlet, &why); }, "already attached");
    refusedWith([&] { return runtime.unplug(ret, 1, &why); }, "is not plugged");
    refusedWith([&] { return runtime.unplug(ret, -1, &why); }, "end -1");
    refusedWith([&] { return runtime.unplug(-3, 1, &why); }, "hose -3 is out of range");
    EXPECT_THROW((void)runtime.socketOccupant(2), std::out_of_range);

    // A free socket takes right-return's free end; then the occupied plate takes it after
    // left-feed leaves.
    const rig::PlugResult intoOutlet = runtime.plug(ret, 1, outlet, &why);
    EXPECT_EQ(intoOutlet.status, Status::Ok) << why;
    EXPECT_EQ(runtime.socketOccupant(outlet).hose, ret);
    ASSERT_EQ(runtime.unplug(feed, 1).status, Status::Ok);
    ASSERT_EQ(runtime.unplug(ret, 1).status, Status::Ok);
    EXPECT_EQ(runtime.socketOccupant(outlet).hose, -1);
    EXPECT_EQ(runtime.plug(ret, 1, plate, &why).status, Status::Ok) << why;
    EXPECT_EQ(runtime.socketOccupant(plate).hose, ret);
    // Plugged from afar into a socket beyond the hose's reach (its other end 0.47 m away, the
    // hose 0.43 m long): every easing frame keeps every segment in its band (bends give way
    // first, as for a moved attachment), and the end stays short of the socket, Infeasible.
    for (int frame = 0; frame < kEasingUpdates; ++frame) {
        runtime.update();
        EXPECT_LE(runtime.frameResult(ret).lengthViolation, 1e-9) << "easing, frame " << frame;
        EXPECT_TRUE(inBand(runtime.hose(ret))) << "easing, frame " << frame;
    }
    // Under the real-time budget the easing's last move goes on pending while it gets nearer;
    // once it no longer does, the bends give way or it rests, within the budget: no update()
    // takes more Newton steps than the budget allows.
    int extra = 0;
    for (; runtime.pending(ret) && extra < 60; ++extra) {
        runtime.update();
        EXPECT_TRUE(inBand(runtime.hose(ret))) << "pending, frame " << extra;
        EXPECT_LE(runtime.frameResult(ret).iterations, runtime.budget().newtonSteps)
            << "pending, frame " << extra;
    }
    EXPECT_FALSE(runtime.pending(ret)) << "still pending after " << extra << " more updates";
    const rig::HoseRuntime::SocketPose port = runtime.socket(plate);
    const int last = runtime.hose(ret).pointCount() - 1;
    const double reach = runtime.hose(ret).restLengthTotal();
    const double span = (port.position - runtime.hose(ret).point(0)).norm();
    ASSERT_GT(span, reach * (1.0 + runtime.description(ret).expansionCoefficient));
    const double short_ = (runtime.hose(ret).point(last) - port.position).norm();
    EXPECT_GT(short_, 0.0);
    EXPECT_EQ(runtime.frameResult(ret).status, Status::Infeasible);
    EXPECT_EQ(runtime.socketOccupant(plate).hose, ret); // held, met once the part comes nearer
    std::cout << "[ socket ] right-return plugged into plate-port " << span
              << " m from its other end (" << reach << " m long): " << short_
              << " m short, every easing frame in the band\n";
}

TEST(HoseRuntimeSockets, AHoseCutWhilePluggedLeavesItsEndInTheSocketOnTheNewPiece)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadSocketRig(folder);
    const int feed = runtime.findHose("left-feed");
    const int plate = runtime.findSocket("plate-port");
    ASSERT_EQ(runtime.unplug(feed, 1).status, Status::Ok);
    ASSERT_EQ(runtime.plug(feed, 1, plate).status, Status::Ok);
    for (int frame = 0; frame < kEasingUpdates; ++frame)
        runtime.update();
    const int middle = runtime.hose(feed).pointCount() / 2;
    const rig::CutResult cut = runtime.cut(feed, middle);
    ASSERT_EQ(cut.status, Status::Ok);
    // The plugged end went with the piece beyond the cut, and the socket knows it.
    const rig::SocketOccupant occupant = runtime.socketOccupant(plate);
    EXPECT_EQ(occupant.hose, cut.newHose);
    EXPECT_EQ(occupant.end, 1);
    ASSERT_GE(occupant.attachment, 0);
    EXPECT_EQ(runtime.attachment(cut.newHose, occupant.attachment).socket, plate);
    const int last = runtime.hose(cut.newHose).pointCount() - 1;
    EXPECT_LT((runtime.hose(cut.newHose).point(last) - runtime.socket(plate).position).norm(),
              1e-9);
    // The cut ends carry no plug: the first piece's new end and the new piece's first end.
    EXPECT_EQ(runtime.description(feed).plugEnd, "");
    EXPECT_EQ(runtime.description(cut.newHose).plugStart, "");
    EXPECT_EQ(runtime.description(cut.newHose).plugEnd, "camlock-19");
    std::string why;
    EXPECT_EQ(runtime.plug(feed, 1, runtime.findSocket("valve-outlet"), &why).status,
              Status::InvalidInput);
    EXPECT_NE(why.find("has no plug"), std::string::npos) << why;
    // Unplugged from the new piece, the socket is free.
    EXPECT_EQ(runtime.unplug(cut.newHose, 1).socket, plate);
    EXPECT_EQ(runtime.socketOccupant(plate).hose, -1);
}

/// The rig-options sample: valve-tail hangs under gravity from the valve, its last point free.
TEST(HoseRuntimeSockets, AnUnpluggedEndFallsWithGravityWhereTheHoseHasIt)
{
    TemporaryFolder folder;
    const fs::path output = folder / "options.glb";
    exportProjectFile(testDataDir() / "rig-options.ctproj", output, roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(output);
    const int tail = runtime.findHose("valve-tail");
    ASSERT_GE(tail, 0);
    ASSERT_TRUE(runtime.description(tail).gravity.enabled);
    // A hand holds the free end where it is (a hose with nothing fixed and nothing held stays
    // where it is); the valve end is unplugged and falls.
    const int n = runtime.hose(tail).pointCount();
    ASSERT_EQ(runtime.grab(tail, n - 1, runtime.hose(tail).point(n - 1)).status, Status::Ok);
    runtime.update();
    const rig::PlugResult unplugged = runtime.unplug(tail, 0);
    ASSERT_EQ(unplugged.status, Status::Ok);
    EXPECT_EQ(unplugged.socket, -1);
    EXPECT_FALSE(runtime.attachment(tail, unplugged.attachment).attached);
    const double startHeight = runtime.hose(tail).point(0).y();
    for (int frame = 0; frame < 10; ++frame) {
        runtime.update();
        EXPECT_TRUE(inBand(runtime.hose(tail))) << "falling, frame " << frame;
    }
    const double drop = startHeight - runtime.hose(tail).point(0).y();
    EXPECT_GT(drop, 1e-3) << "the unplugged end did not fall";
    std::cout << "[ socket ] valve-tail unplugged: its end fell " << drop << " m in 10 updates\n";
    std::string why;
    EXPECT_EQ(runtime.unplug(tail, 0, &why).status, Status::InvalidInput);
    EXPECT_NE(why.find("is not plugged"), std::string::npos) << why;
}

} // namespace
} // namespace chaintube::exporting::testing
