// The C++ runtime's figures for the C ABI tests: loads an export with rig::HoseRuntime, runs
// four frames of inputs chosen from the rig (a scene part moved, a point grabbed, grabbed out
// of reach, released and the part moved back, a frame without input), and writes the inputs
// and, after every update, every hose's frame result, joint poses and surface to a reference
// file. The C and C# tests replay the inputs through the C ABI and compare.
//
//   capi_reference <export.glb> <reference.txt>
//
// Reference lines (numbers %.17g, floats %.9g: both read back exactly):
//   rig <hoses> <nodes>
//   hose <hose> <points> <joints> <grabbable> <vertices> <indices> <static> <restLength>
//        <outerRadius> <id…>                    the id runs to the end of the line
//   node-name <node> <name…>                    find_node(name) gives <node>
//   move <node> <10 TRS numbers>                input: chaintube_rig_set_node_transform
//   grab <hose> <point> <x> <y> <z>             input: chaintube_rig_grab, then its result:
//   grab-result <result>
//   release <hose>                              input: chaintube_rig_release
//   update                                      input: chaintube_rig_update
//   result <hose> <result>                      chaintube_rig_hose_result
//   pose <hose> <joint> <node> <10 local> <7 world>
//   surface <hose> <vertices> <sum of positions> <sum of normals> <sum of indices> <sum of uvs>
//   vertex <hose> <vertex> <px> <py> <pz> <nx> <ny> <nz>   every 7th vertex
//   attachments <hose> <count>                  chaintube_rig_attachment_count
//   socket <socket> <node> <occupant hose> <end> <attachment> <3 position> <3 axis> <id…>
//                                               chaintube_rig_socket_info (after each update)
//   unplug <hose> <end> <socket left>           input: chaintube_rig_unplug, its *socket
//   plug <hose> <end> <socket> <attachment>     input: chaintube_rig_plug, its *attachment
//   release-snap <hose> <socket>                input: chaintube_rig_release_snap, its *socket
//   reel <hose> <end> <clip> <length> <min> <max>   input: chaintube_rig_reel, then its result:
//   reel-result <paid> <restLength> <largestMove> <clamped> <added> <removed> <points>
//   pull <hose> <attachment> <node> <first> <last> <tautness> <strain> <3 direction> <3 force>
//                                               chaintube_rig_attachment_pull, force at
//                                               kPullStiffness (EA, N per unit strain)
// where <result> is: status blocked movedPoints contacts lengthViolation angleViolation
// grabError penetration (status 0 Ok, 1 Clamped, 2 Infeasible).
#include <algorithm>
#include <chaintube/export/runtime.h>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>

namespace {

using namespace chaintube;

/// The axial stiffness the pulls' forces are written for (newtons per unit strain; the C and C#
/// replays pass the same).
constexpr double kPullStiffness = 1e4;
/// Updates of 1/90 s a plugged end takes to ease in (HoseRuntime::kSnapSeconds).
constexpr int kEasingUpdates = 5;

int statusCode(Status status)
{
    switch (status) {
    case Status::Ok:
        return 0;
    case Status::Clamped:
        return 1;
    case Status::Infeasible:
        return 2;
    case Status::InvalidInput:
        return -1;
    }
    return -1;
}

void writeResult(std::FILE* out, const UpdateResult& r)
{
    std::fprintf(out, "%d %d %d %d %.17g %.17g %.17g %.17g\n", statusCode(r.status),
                 r.blocked ? 1 : 0, r.movedPoints, r.contacts, r.lengthViolation, r.angleViolation,
                 r.grabError, r.penetration);
}

void writeState(std::FILE* out, const rig::HoseRuntime& runtime)
{
    for (int h = 0; h < runtime.hoseCount(); ++h) {
        std::fprintf(out, "result %d ", h);
        writeResult(out, runtime.frameResult(h));
        const std::vector<rig::JointPose>& poses = runtime.jointPoses(h);
        for (size_t j = 0; j < poses.size(); ++j) {
            const rig::JointPose& p = poses[j];
            std::fprintf(out,
                         "pose %d %zu %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g "
                         "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                         h, j, p.node, p.local.translation.x(), p.local.translation.y(),
                         p.local.translation.z(), p.local.rotation.x(), p.local.rotation.y(),
                         p.local.rotation.z(), p.local.rotation.w(), p.local.scale.x(),
                         p.local.scale.y(), p.local.scale.z(), p.world.translation.x(),
                         p.world.translation.y(), p.world.translation.z(), p.world.rotation.x(),
                         p.world.rotation.y(), p.world.rotation.z(), p.world.rotation.w());
        }
        for (int a = 0; a < runtime.attachmentCount(h); ++a) {
            const AttachmentPull& pull = runtime.attachmentPull(h, a);
            const rig::LiveAttachment& d = runtime.attachment(h, a);
            const Vec3 force = pull.force(kPullStiffness);
            std::fprintf(
                out, "pull %d %d %d %d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", h, a,
                d.node, d.firstPoint, d.lastPoint, pull.tautness, pull.strain, pull.direction.x(),
                pull.direction.y(), pull.direction.z(), force.x(), force.y(), force.z());
        }
        const std::vector<float> positions = runtime.worldPositions(h);
        const std::span<const float> normals = runtime.surface(h).normals();
        const SurfaceTopology& topology = runtime.surface(h).topology();
        double positionSum = 0.0, normalSum = 0.0, indexSum = 0.0, uvSum = 0.0;
        for (size_t k = 0; k < positions.size(); ++k) {
            positionSum += positions[k];
            normalSum += normals[k];
        }
        for (std::uint32_t index : topology.indices)
            indexSum += index;
        for (float uv : topology.uvs)
            uvSum += uv;
        const size_t vertices = positions.size() / 3;
        std::fprintf(out, "surface %d %zu %.17g %.17g %.17g %.17g\n", h, vertices, positionSum,
                     normalSum, indexSum, uvSum);
        for (size_t v = 0; v < vertices; v += 7)
            std::fprintf(out, "vertex %d %zu %.9g %.9g %.9g %.9g %.9g %.9g\n", h, v,
                         positions[3 * v], positions[3 * v + 1], positions[3 * v + 2],
                         normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
    }
}

void writeSockets(std::FILE* out, const rig::HoseRuntime& runtime)
{
    for (int k = 0; k < runtime.socketCount(); ++k) {
        const rig::HoseRuntime::SocketPose pose = runtime.socket(k);
        const rig::SocketOccupant occupant = runtime.socketOccupant(k);
        std::fprintf(out, "socket %d %d %d %d %d %.17g %.17g %.17g %.17g %.17g %.17g %s\n", k,
                     pose.description->node, occupant.hose, occupant.end, occupant.attachment,
                     pose.position.x(), pose.position.y(), pose.position.z(), pose.axis.x(),
                     pose.axis.y(), pose.axis.z(), pose.description->id.c_str());
    }
}

void writeMove(std::FILE* out, int node, const rig::NodeTransform& t)
{
    std::fprintf(out, "move %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", node,
                 t.translation.x(), t.translation.y(), t.translation.z(), t.rotation.x(),
                 t.rotation.y(), t.rotation.z(), t.rotation.w(), t.scale.x(), t.scale.y(),
                 t.scale.z());
}

/// Sets the transform as the C ABI does: the numbers as written, read back exactly.
void move(std::FILE* out, rig::HoseRuntime& runtime, int node, const rig::NodeTransform& t)
{
    writeMove(out, node, t);
    for (const rig::HoseUpdate& update : runtime.setNodeTransform(node, t))
        if (update.result.status == Status::InvalidInput)
            throw Error("node " + std::to_string(node) + ": the runtime refused the move");
}

void grab(std::FILE* out, rig::HoseRuntime& runtime, int hose, int point, const Vec3& target)
{
    std::fprintf(out, "grab %d %d %.17g %.17g %.17g\n", hose, point, target.x(), target.y(),
                 target.z());
    const UpdateResult result = runtime.grab(hose, point, target);
    if (result.status == Status::InvalidInput)
        throw Error("hose " + std::to_string(hose) + ": the runtime refused the grab");
    std::fprintf(out, "grab-result ");
    writeResult(out, result);
}

void update(std::FILE* out, rig::HoseRuntime& runtime, bool state = true)
{
    std::fprintf(out, "update\n");
    runtime.update();
    if (state) {
        writeState(out, runtime);
        writeSockets(out, runtime);
    }
}

/// Sockets: the first hose with a plug tag on its last end is unplugged there, carried by its
/// end point to 20 cm above the socket nearest its first point that takes it and down to 1 cm
/// above it, released there (it snaps in) and eased in; then unplugged and plugged into the
/// next socket with its tag. Nothing when the rig has no such hose and two such sockets.
void socketFrames(std::FILE* out, rig::HoseRuntime& runtime)
{
    int hose = -1;
    for (int h = 0; h < runtime.hoseCount() && hose < 0; ++h)
        if (!runtime.description(h).plugEnd.empty() && !runtime.description(h).isStatic) hose = h;
    if (hose < 0) return;
    const std::string& tag = runtime.description(hose).plugEnd;
    std::vector<int> sockets;
    for (int k = 0; k < runtime.socketCount(); ++k)
        if (runtime.socket(k).description->tag == tag) sockets.push_back(k);
    if (sockets.size() < 2) return;
    const int n = runtime.hose(hose).pointCount();
    const Vec3 base = runtime.hose(hose).point(0);
    std::sort(sockets.begin(), sockets.end(), [&](int a, int b) {
        return (runtime.socket(a).position - base).norm() <
               (runtime.socket(b).position - base).norm();
    });
    const int first = sockets[0], second = sockets[1];

    const auto unplug = [&](int end) {
        const rig::PlugResult result = runtime.unplug(hose, end);
        if (!result) throw Error("the runtime refused the unplug");
        std::fprintf(out, "unplug %d %d %d\n", hose, end, result.socket);
    };
    unplug(1);
    update(out, runtime);
    const rig::HoseRuntime::SocketPose port = runtime.socket(first);
    Vec3 beyond = port.position - base;
    beyond -= beyond.dot(port.axis) * port.axis;
    beyond.normalize();
    const Vec3 above = port.position + 0.2 * port.axis + 0.06 * beyond;
    const Vec3 release = port.position + 0.01 * port.axis;
    for (const auto& [to, frames] : {std::pair{above, 8}, std::pair{release, 6}}) {
        const Vec3 from = runtime.hose(hose).point(n - 1);
        for (int frame = 1; frame <= frames; ++frame) {
            grab(out, runtime, hose, n - 1, from + (to - from) * (double(frame) / frames));
            update(out, runtime);
        }
    }
    const rig::PlugResult snapped = runtime.release(hose);
    std::fprintf(out, "release-snap %d %d\n", hose, snapped.socket);
    if (snapped.socket != first) throw Error("the released end did not snap into its socket");
    for (int frame = 0; frame <= kEasingUpdates; ++frame)
        update(out, runtime);
    unplug(1);
    const rig::PlugResult plugged = runtime.plug(hose, 1, second);
    if (!plugged) throw Error("the runtime refused the plug");
    std::fprintf(out, "plug %d %d %d %d\n", hose, 1, second, plugged.attachment);
    for (int frame = 0; frame <= kEasingUpdates; ++frame)
        update(out, runtime);
}

/// Reel: a frame's length at `end` of a hose between the bounds, and what it did. Returns the
/// length paid.
double reel(std::FILE* out, rig::HoseRuntime& runtime, int hose, double length, double minLength,
            double maxLength)
{
    std::fprintf(out, "reel %d 0 -1 %.17g %.17g %.17g\n", hose, length, minLength, maxLength);
    const ReelResult r = runtime.reel(hose, HoseEnd::Start, length, minLength, maxLength);
    if (r.status == Status::InvalidInput)
        throw Error("hose " + std::to_string(hose) +
                    ": the runtime refused the reel: " + r.message);
    std::fprintf(out, "reel-result %.17g %.17g %.17g %d %d %d %d\n", r.paid,
                 runtime.hose(hose).restLengthTotal(), r.largestMove, r.clamped ? 1 : 0,
                 r.segmentsAdded, r.segmentsRemoved, runtime.hose(hose).pointCount());
    return r.paid;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 3) {
        std::fprintf(stderr, "usage: capi_reference <export.glb> <reference.txt>\n");
        return 2;
    }
    try {
        rig::HoseRuntime runtime = rig::HoseRuntime::load(argv[1]);
        std::FILE* out = std::fopen(argv[2], "w");
        if (!out) throw Error(std::string(argv[2]) + ": cannot be written");
        std::fprintf(out, "rig %d %d\n", runtime.hoseCount(), runtime.nodeCount());
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            const rig::RigHose& d = runtime.description(h);
            std::fprintf(out, "hose %d %d %zu %zu %zu %zu %d %.17g %.17g %s\n", h,
                         runtime.hose(h).pointCount(), runtime.jointPoses(h).size(),
                         d.grabbablePoints.size(), runtime.surface(h).vertexCount(),
                         runtime.surface(h).topology().indices.size(), d.isStatic ? 1 : 0,
                         runtime.hose(h).restLengthTotal(), runtime.hose(h).outerRadius(),
                         d.id.c_str());
            std::fprintf(out, "attachments %d %d\n", h, runtime.attachmentCount(h));
        }
        // The part to move: the first attachment node of a hose that deforms; the point to
        // grab: the middle free point of the first hose that has free points.
        int part = -1, grabbed = -1;
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            const rig::RigHose& d = runtime.description(h);
            if (d.isStatic) continue;
            for (const rig::RigAttachment& a : d.attachments)
                if (part < 0 && a.node >= 0) part = a.node;
            if (grabbed < 0 && !d.grabbablePoints.empty()) grabbed = h;
        }
        if (part < 0 || grabbed < 0) throw Error("no attachment node or no grabbable point");
        const std::string& partName = runtime.node(part).name;
        if (!partName.empty() && runtime.findNode(partName) == part)
            std::fprintf(out, "node-name %d %s\n", part, partName.c_str());
        const std::vector<int>& free = runtime.description(grabbed).grabbablePoints;
        const int point = free[free.size() / 2];
        const rig::NodeTransform original = runtime.node(part).local;

        rig::NodeTransform moved = original;
        moved.translation += Vec3(0.02, -0.015, 0.01);
        moved.rotation = original.rotation * Quat(Eigen::AngleAxisd(0.05, Vec3::UnitY()));
        // Frame 1: the part moves, a point is grabbed a few centimetres away.
        move(out, runtime, part, moved);
        const Vec3 start = runtime.hose(grabbed).point(point);
        grab(out, runtime, grabbed, point, start + Vec3(0.03, 0.04, -0.02));
        update(out, runtime);
        // Frame 2: the hand goes far beyond reach.
        grab(out, runtime, grabbed, point, start + Vec3(1.0, 0.5, 0.0));
        update(out, runtime);
        // Frame 3: the hand lets go, the part goes back.
        std::fprintf(out, "release %d\n", grabbed);
        if (!runtime.release(grabbed)) throw Error("release refused");
        move(out, runtime, part, original);
        update(out, runtime);
        // Frame 4: no input (gravity hoses go on falling).
        update(out, runtime);
        socketFrames(out, runtime);
        // Frames 5 …: 0.3 m paid out of the reel at the first end and reeled back in.
        int reeled = -1;
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            const rig::RigHose& d = runtime.description(h);
            bool startFixed = false;
            for (const rig::RigAttachment& a : d.attachments)
                startFixed = startFixed || a.firstPoint == 0;
            if (d.isStatic || !startFixed || d.grabbablePoints.empty()) continue;
            if (reeled < 0 || (runtime.description(reeled).gravity.enabled && !d.gravity.enabled))
                reeled = h;
        }
        if (reeled < 0) throw Error("no hose with a fixed first end to reel");
        const double step = 0.5 / 90.0, total = runtime.hose(reeled).restLengthTotal();
        const double maxLength = std::numeric_limits<double>::max(); // %.17g reads back
        int frame = 0;
        for (const double direction : {+1.0, -1.0}) {
            double left = 0.3;
            for (int k = 0; k < 60 && left > 1e-12; ++k, ++frame) {
                left -= std::abs(reel(out, runtime, reeled, direction * std::min(step, left),
                                      0.5 * total, maxLength));
                update(out, runtime, frame % 6 == 5);
            }
        }
        writeState(out, runtime);
        if (std::fclose(out) != 0) throw Error(std::string(argv[2]) + ": cannot be written");
        std::printf("capi_reference: %s: moved node %d (\"%s\"), grabbed hose %d point %d, reeled "
                    "hose %d 0.3 m out and in again over %d frames -> %s\n",
                    argv[1], part, partName.c_str(), grabbed, point, reeled, frame, argv[2]);
        return 0;
    } catch (const std::exception& error) {
        std::fprintf(stderr, "capi_reference: %s\n", error.what());
        return 1;
    }
}
