#include "chaintube/export/runtime.h"

#include "chaintube/cut.h"
#include "chaintube/formats/collider_exemption.h"
#include "gltf_container.h"
#include "runtime_internal.h"
#include "transform_math.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace chaintube::rig {

using detail::badEndText;
using detail::hoseOutOfRangeText;
using detail::restArcs;
using detail::runningHoseName;

namespace {
/// HoseRuntime::poseJoints: a parent node's world transform whose columns are orthogonal and of
/// equal length to this (relative) is a rotation and a uniform scale.
constexpr double kSimilar = 1e-6;

using Json = nlohmann::json;
namespace fs = std::filesystem;

NodeTransform nodeTransformOf(const Json& node, const std::string& where)
{
    NodeTransform trs;
    const auto numbers = [&](const char* key, size_t count) {
        std::vector<double> values;
        const Json& array = node.at(key);
        if (!array.is_array() || array.size() != count)
            throw Error(where + "/" + key + ": expected " + std::to_string(count) + " numbers");
        for (const Json& value : array)
            values.push_back(value.get<double>());
        return values;
    };
    if (node.contains("matrix")) {
        const std::vector<double> m = numbers("matrix", 16);
        detail::Affine affine;
        for (int column = 0; column < 4; ++column)
            for (int row = 0; row < 4; ++row)
                affine(row, column) = m[static_cast<size_t>(4 * column + row)];
        detail::decompose(affine, trs);
        return trs;
    }
    if (node.contains("translation")) {
        const auto t = numbers("translation", 3);
        trs.translation = Vec3(t[0], t[1], t[2]);
    }
    if (node.contains("rotation")) {
        const auto r = numbers("rotation", 4);
        trs.rotation = Quat(r[3], r[0], r[1], r[2]).normalized();
    }
    if (node.contains("scale")) {
        const auto s = numbers("scale", 3);
        trs.scale = Vec3(s[0], s[1], s[2]);
    }
    return trs;
}

bool finite(const NodeTransform& trs)
{
    return trs.translation.allFinite() && trs.rotation.coeffs().allFinite() &&
           trs.scale.allFinite() && trs.rotation.norm() > 0.5;
}

/// Where an export's parts come from: a file and the files beside it, or memory.
struct ExportParts
{
    std::string name; ///< the file, or the in-memory export's name
    detail::GltfContainer container;
    detail::ExternalBuffer buffer; ///< a buffer with a uri
    /// The sidecar descriptor: its name (for messages and the report) and a reader that throws
    /// when it is absent, naming what was looked for.
    std::string sidecarName;
    std::function<std::string()> sidecar;
};

HoseRigDescriptor descriptorOf(const Json& gltf, const ExportParts& parts, RuntimeLoadReport& r)
{
    if (gltf.contains("extensions") && gltf["extensions"].contains(kExtensionName)) {
        r.descriptorSource = parts.name + "#" + kExtensionName;
        return parseDescriptor(gltf["extensions"][kExtensionName].dump(), r.descriptorSource);
    }
    const std::string text = parts.sidecar();
    r.descriptorSource = parts.sidecarName;
    r.warnings.push_back(parts.name + ": no " + kExtensionName +
                         " extension; using the descriptor in " + parts.sidecarName);
    return parseDescriptor(text, r.descriptorSource);
}

HoseRuntime loadParts(const ExportParts& parts, RuntimeLoadReport* report)
{
    const std::string& name = parts.name;
    Json gltf;
    try {
        gltf = Json::parse(parts.container.json);
    } catch (const Json::exception& error) {
        throw Error(name + ": malformed glTF JSON: " + error.what());
    }
    std::vector<RigNode> nodes;
    try {
        const Json& jsonNodes = gltf.value("nodes", Json::array());
        nodes.resize(jsonNodes.size());
        for (size_t i = 0; i < jsonNodes.size(); ++i) {
            const std::string where = name + ": /nodes/" + std::to_string(i);
            nodes[i].name = jsonNodes[i].value("name", "");
            nodes[i].local = nodeTransformOf(jsonNodes[i], where);
            for (const Json& child : jsonNodes[i].value("children", Json::array())) {
                const auto c = child.get<long long>();
                if (c < 0 || static_cast<size_t>(c) >= jsonNodes.size() ||
                    nodes[static_cast<size_t>(c)].parent >= 0)
                    throw Error(where + "/children: invalid or repeated child " +
                                std::to_string(c));
                nodes[static_cast<size_t>(c)].parent = static_cast<int>(i);
            }
        }
    } catch (const Json::exception& error) {
        throw Error(name + ": /nodes: " + error.what());
    }

    RuntimeLoadReport local;
    RuntimeLoadReport& r = report ? *report : local;
    HoseRigDescriptor descriptor = descriptorOf(gltf, parts, r);
    const int skins = static_cast<int>(gltf.value("skins", Json::array()).size());
    const std::vector<std::string> problems =
        checkAgainstGltf(descriptor, static_cast<int>(nodes.size()), skins);
    if (!problems.empty()) throw Error(r.descriptorSource + problems.front());
    // Collider meshes: every triangle primitive of each collider node's mesh.
    std::vector<ColliderMesh> colliderMeshes;
    if (!descriptor.colliders.empty()) {
        detail::GltfFile withBuffers;
        withBuffers.buffers =
            detail::gatherBuffers(gltf, parts.container.binChunk, name, parts.buffer);
        withBuffers.json = std::move(gltf);
        for (size_t c = 0; c < descriptor.colliders.size(); ++c) {
            const int node = descriptor.colliders[c];
            const std::string where = r.descriptorSource + ": /colliders/" + std::to_string(c);
            ColliderMesh mesh;
            try {
                const Json& jsonNode = withBuffers.json.at("nodes").at(static_cast<size_t>(node));
                if (!jsonNode.contains("mesh"))
                    throw Error(where + ": node " + std::to_string(node) + " has no mesh");
                const Json& primitives = withBuffers.json.at("meshes")
                                             .at(jsonNode["mesh"].get<size_t>())
                                             .at("primitives");
                for (const Json& primitive : primitives) {
                    if (primitive.value("mode", 4) != 4) continue; // only triangles collide
                    const std::vector<float> positions = detail::floatsOf(
                        withBuffers, primitive.at("attributes").at("POSITION").get<int>(), where);
                    const auto first = static_cast<std::uint32_t>(mesh.positions.size() / 3);
                    std::vector<std::uint32_t> indices;
                    if (primitive.contains("indices"))
                        indices =
                            detail::indicesOf(withBuffers, primitive["indices"].get<int>(), where);
                    else
                        for (std::uint32_t v = 0; v < positions.size() / 3; ++v)
                            indices.push_back(v);
                    for (std::uint32_t index : indices)
                        mesh.indices.push_back(first + index);
                    mesh.positions.insert(mesh.positions.end(), positions.begin(), positions.end());
                }
            } catch (const Json::exception& error) {
                throw Error(where + ": the node's mesh cannot be read: " + error.what());
            }
            colliderMeshes.push_back(std::move(mesh));
        }
    }
    return HoseRuntime::fromDescriptor(std::move(descriptor), std::move(nodes), &r, colliderMeshes);
}

} // namespace

HoseRuntime HoseRuntime::load(const fs::path& file, RuntimeLoadReport* report)
{
    ExportParts parts;
    parts.name = file.string();
    parts.container = detail::splitGltf(parts.name, detail::readFileBytes(file));
    parts.buffer = [&](size_t, const std::string& uri, const std::string& where) {
        return detail::readBufferBeside(file, uri, where);
    };
    fs::path sidecar = file;
    sidecar.replace_extension(".hoses.json");
    parts.sidecarName = sidecar.string();
    parts.sidecar = [&] {
        if (!fs::exists(sidecar))
            throw Error(file.string() + ": has no " + kExtensionName + " extension and no " +
                        sidecar.filename().string() + " beside it");
        return detail::readFileBytes(sidecar);
    };
    return loadParts(parts, report);
}

HoseRuntime HoseRuntime::loadFromMemory(const ExportInMemory& source, RuntimeLoadReport* report)
{
    ExportParts parts;
    parts.name = source.name;
    parts.container = detail::splitGltf(parts.name, source.gltf);
    parts.buffer = [&](size_t index, const std::string& uri, const std::string& where) {
        if (index >= source.buffers.size() || source.buffers[index].data() == nullptr)
            throw Error(where + ": the buffer \"" + uri +
                        "\" was not given (expected the bytes of "
                        "buffer " +
                        std::to_string(index) + " in the export's buffers)");
        return std::string(source.buffers[index]);
    };
    parts.sidecarName = fs::path(source.name).replace_extension(".hoses.json").string();
    parts.sidecar = [&] {
        if (source.sidecarDescriptor.empty())
            throw Error(source.name + ": has no " + kExtensionName +
                        " extension and no sidecar descriptor was given");
        return std::string(source.sidecarDescriptor);
    };
    return loadParts(parts, report);
}

std::shared_ptr<MeshCollider> HoseRuntime::buildCollider(const ColliderMesh& mesh,
                                                         const Eigen::Matrix4d& nodeWorld)
{
    const Frame frame = rigidPart(nodeWorld);
    // What the rigid frame leaves of the node's world transform (scale, shear) goes into the
    // vertices, so that frame.apply(vertex) is the vertex's world position.
    const Eigen::Matrix4d baked = detail::matrixOf(frame).inverse() * nodeWorld;
    std::vector<Vec3> positions(mesh.positions.size() / 3);
    for (size_t v = 0; v < positions.size(); ++v)
        positions[v] = (baked * Eigen::Vector4d(mesh.positions[3 * v], mesh.positions[3 * v + 1],
                                                mesh.positions[3 * v + 2], 1.0))
                           .head<3>();
    return MeshCollider::fromArrays(positions, mesh.indices, frame);
}

HoseRuntime HoseRuntime::fromDescriptor(HoseRigDescriptor descriptor, std::vector<RigNode> nodes,
                                        RuntimeLoadReport* report,
                                        const std::vector<ColliderMesh>& colliderMeshes)
{
    if (colliderMeshes.size() != descriptor.colliders.size())
        throw Error("descriptor/colliders: " + std::to_string(descriptor.colliders.size()) +
                    " collider node(s) but " + std::to_string(colliderMeshes.size()) +
                    " collider mesh(es) given");
    const std::vector<std::string> problems =
        checkAgainstGltf(descriptor, static_cast<int>(nodes.size()), 1 << 30);
    if (!problems.empty()) throw Error("descriptor" + problems.front());
    for (size_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].parent >= static_cast<int>(i) && nodes[i].parent >= 0) {
            // Parents may come after children in glTF; the world pass handles any order, but a
            // cycle must be refused.
            int steps = 0;
            for (int p = nodes[i].parent; p >= 0; p = nodes[static_cast<size_t>(p)].parent)
                if (++steps > static_cast<int>(nodes.size()))
                    throw Error("glTF node " + std::to_string(i) + ": its parents form a cycle");
        }

    HoseRuntime runtime;
    runtime.m_descriptor = std::move(descriptor);
    runtime.m_nodes = std::move(nodes);
    runtime.recomputeWorld();
    for (size_t h = 0; h < runtime.m_descriptor.hoses.size(); ++h) {
        const RigHose& d = runtime.m_descriptor.hoses[h];
        const std::string at = "/hoses/" + std::to_string(h);
        std::vector<int> attachmentIds;
        Hose hose = rebuildHose(d, &attachmentIds);
        // A project's hose lies on its route with its own length, stretched or compressed
        // within its band at most; report, rather than hide, one exported beyond the band
        // (rebuildHose keeps its rest lengths: the first update pulls it back in).
        if (!withinStretchBand(d) && report)
            report->warnings.push_back(at + "/restLengths: the axis was exported with segments "
                                            "beyond their stretch band; the runtime keeps the "
                                            "exported rest lengths, so the hose starts "
                                            "overstretched or compressed");
        HoseSurface surface(hose); // as the library does after building: same twist seed
        // Ids: the descriptor's attachments', then its clips' (rebuildHose).
        std::vector<int> clipIds(attachmentIds.begin() +
                                     static_cast<std::ptrdiff_t>(d.attachments.size()),
                                 attachmentIds.end());
        RunningHose running{std::move(hose),
                            std::move(surface),
                            std::move(clipIds),
                            {},
                            {},
                            {},
                            {},
                            true,
                            0,
                            {},
                            {},
                            {},
                            {},
                            {},
                            {}};
        for (size_t k = 0; k < d.attachments.size(); ++k) {
            const RigAttachment& a = d.attachments[k];
            running.live.push_back(
                {a.node, a.offset, a.firstPoint, a.lastPoint, true, attachmentIds[k]});
        }
        running.grabbable = d.grabbablePoints;
        for (int joint : d.jointNodes)
            running.jointParents.push_back(runtime.m_nodes[static_cast<size_t>(joint)].parent);
        running.hose.setBudget(runtime.m_budget);
        runtime.m_hoses.push_back(std::move(running));
    }
    for (size_t c = 0; c < runtime.m_descriptor.colliders.size(); ++c) {
        const int node = runtime.m_descriptor.colliders[c];
        try {
            runtime.m_colliders.push_back(
                buildCollider(colliderMeshes[c], runtime.m_world[static_cast<size_t>(node)]));
        } catch (const InvalidArgument& error) {
            throw Error("descriptor/colliders/" + std::to_string(c) + ": node " +
                        std::to_string(node) + ": " + error.what());
        }
    }
    for (size_t h = 0; h < runtime.m_hoses.size() && !runtime.m_colliders.empty(); ++h)
        runtime.chooseColliders(h);
    // A gravity hose is exported as it hangs (formats::settleUnderGravity): it starts at rest and
    // falls again once an input moves it, instead of re-settling (creeping) from the file.
    for (RunningHose& running : runtime.m_hoses)
        if (running.hose.spec().gravity.enabled) running.hose.markSettled();
    runtime.refresh(); // surfaces and poses as exported
    return runtime;
}

void HoseRuntime::chooseColliders(size_t hose)
{
    // Every hose stays outside the colliders except the nodes it is attached to and their
    // ancestors (its ends sit in those: formats/collider_exemption.h, the clearance check's rule),
    // and those it was unplugged from (the end starts inside the part, and would stick there).
    RunningHose& running = m_hoses[hose];
    const RigHose& d = m_descriptor.hoses[hose];
    const auto parentOf = [&](int n) { return m_nodes[static_cast<size_t>(n)].parent; };
    std::vector<std::shared_ptr<const MeshCollider>> used;
    for (size_t c = 0; c < m_colliders.size(); ++c) {
        const int collider = m_descriptor.colliders[c];
        const bool exempt =
            std::any_of(running.live.begin(), running.live.end(),
                        [&](const LiveAttachment& a) {
                            return formats::attachmentExempts(a.node, collider, parentOf);
                        }) ||
            std::any_of(d.clips.begin(), d.clips.end(), [&](const RigClip& a) {
                return formats::attachmentExempts(a.node, collider, parentOf);
            });
        if (!exempt) used.push_back(m_colliders[c]);
    }
    if (used != running.hose.colliders()) running.hose.setColliders(std::move(used));
}

void HoseRuntime::findGrabbable(RunningHose& running, const RigHose& description)
{
    running.grabbable.clear();
    if (description.isStatic) return;
    std::vector<char> fixed(static_cast<size_t>(running.hose.pointCount()), 0);
    for (const LiveAttachment& a : running.live)
        if (a.attached)
            for (int i = a.firstPoint; i <= a.lastPoint; ++i)
                fixed[static_cast<size_t>(i)] = 1;
    for (size_t i = 0; i < fixed.size(); ++i)
        if (!fixed[i]) running.grabbable.push_back(static_cast<int>(i));
}

const LiveAttachment& HoseRuntime::attachment(int hose, int attachment) const
{
    const RunningHose& running = m_hoses.at(static_cast<size_t>(hose));
    if (attachment < 0 || static_cast<size_t>(attachment) >= running.live.size())
        throw std::out_of_range("hose " + std::to_string(hose) + ": attachment " +
                                std::to_string(attachment) + " is out of range");
    return running.live[static_cast<size_t>(attachment)];
}

const std::vector<int>& HoseRuntime::grabbablePoints(int hose) const
{
    return m_hoses.at(static_cast<size_t>(hose)).grabbable;
}

namespace {
UpdateResult refused(std::string* why, std::string text)
{
    if (why) *why = std::move(text);
    UpdateResult result;
    result.status = Status::InvalidInput;
    return result;
}
} // namespace

UpdateResult HoseRuntime::detachEnd(int hose, int attachment, std::string* why)
{
    if (hose < 0 || hose >= hoseCount()) return refused(why, hoseOutOfRangeText(hose, hoseCount()));
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    const RigHose& d = m_descriptor.hoses[static_cast<size_t>(hose)];
    const std::string name = runningHoseName(hose, d);
    if (attachment < 0 || static_cast<size_t>(attachment) >= running.live.size())
        return refused(why, "attachment " + std::to_string(attachment) +
                                " is out of range: " + name + " has " +
                                std::to_string(running.live.size()) + " attachments");
    if (d.isStatic) return refused(why, name + " is static: its attachments never change");
    LiveAttachment& live = running.live[static_cast<size_t>(attachment)];
    if (!live.attached)
        return refused(why, "attachment " + std::to_string(attachment) + " of " + name +
                                " is already detached");
    running.hose.detach(live.id);
    live.attached = false;
    live.id = -1;
    findGrabbable(running, d);
    running.pullsStale = true;
    return UpdateResult(); // nothing moved yet: the freed points fall from the next update()
}

UpdateResult HoseRuntime::attachEnd(int hose, int end, int node, const Frame& localFrame,
                                    int* attachment, std::string* why)
{
    if (hose < 0 || hose >= hoseCount()) return refused(why, hoseOutOfRangeText(hose, hoseCount()));
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    const RigHose& d = m_descriptor.hoses[static_cast<size_t>(hose)];
    const std::string name = runningHoseName(hose, d);
    if (node < -1 || node >= nodeCount())
        return refused(why, "node " + std::to_string(node) + " is out of range: expected -1 (the " +
                                "world) or 0 to " + std::to_string(nodeCount() - 1));
    if (d.isStatic) return refused(why, name + " is static: its attachments never change");
    if (end != 0 && end != 1) return refused(why, badEndText(end));
    if (!localFrame.translation.allFinite() || !localFrame.rotation.coeffs().allFinite() ||
        localFrame.rotation.norm() <= 0.5)
        return refused(why, "the local frame is not finite or its rotation is not a unit "
                            "quaternion (length above 0.5, normalised)");
    const int n = running.hose.pointCount();
    const int first = end == 0 ? 0 : n - 2;
    const int last = first + 1;
    const auto overlaps = [&](int a, int b) { return a <= last && b >= first; };
    for (size_t k = 0; k < running.live.size(); ++k)
        if (running.live[k].attached &&
            overlaps(running.live[k].firstPoint, running.live[k].lastPoint))
            return refused(why, "end " + std::to_string(end) + " of " + name +
                                    " is already attached (attachment " + std::to_string(k) +
                                    " fixes points " + std::to_string(running.live[k].firstPoint) +
                                    " to " + std::to_string(running.live[k].lastPoint) + ")");
    for (size_t c = 0; c < d.clips.size(); ++c) {
        const Hose::Attachment& held = clip(hose, static_cast<int>(c));
        if (overlaps(held.first, held.first + 1))
            return refused(why, "end " + std::to_string(end) + " of " + name + " is held by clip " +
                                    std::to_string(c));
    }

    const Frame current = endFrame(running, end);
    Frame offset = localFrame;
    offset.rotation.normalize();
    const Frame target = (node >= 0 ? nodeWorldFrame(node) : Frame()) * offset;
    if (running.hose.heldPoint() >= first && running.hose.heldPoint() <= last)
        running.hose.releaseGrab(); // the hand hands the end over
    const int id = running.hose.attach(first, last, current);
    running.live.push_back({node, offset, first, last, true, id});
    if (attachment) *attachment = static_cast<int>(running.live.size()) - 1;
    findGrabbable(running, d);
    running.pullsStale = true;
    if (!m_colliders.empty()) chooseColliders(static_cast<size_t>(hose));
    const UpdateResult result = running.hose.moveAttachment(id, target);
    combine(running.pendingResult, result);
    return result;
}

Frame HoseRuntime::endFrame(const RunningHose& running, int end)
{
    const int n = running.hose.pointCount();
    const Vec3 tip = running.hose.point(end == 0 ? 0 : n - 1);
    const Vec3 inner = running.hose.point(end == 0 ? 1 : n - 2);
    const Vec3 z = (tip - inner).normalized();
    const std::vector<RingFrame>& rings = running.surface.frames();
    Vec3 x = rings.empty() ? Vec3::UnitX() : rings[end == 0 ? 0 : rings.size() - 1].alignment;
    x -= x.dot(z) * z;
    if (x.norm() < 1e-6) x = z.unitOrthogonal();
    x.normalize();
    Eigen::Matrix3d axes;
    axes.col(0) = x;
    axes.col(1) = z.cross(x);
    axes.col(2) = z;
    Frame frame;
    frame.translation = tip;
    frame.rotation = Quat(axes).normalized();
    return frame;
}

// ---- Sockets: plug, unplug, snap-in on release, easing ----

int HoseRuntime::attachmentAtEnd(const RunningHose& running, int end)
{
    const int last = running.hose.pointCount() - 1;
    for (size_t k = 0; k < running.live.size(); ++k) {
        const LiveAttachment& a = running.live[k];
        if (a.attached && (end == 0 ? a.firstPoint == 0 : a.lastPoint == last))
            return static_cast<int>(k);
    }
    return -1;
}

SocketOccupant HoseRuntime::socketOccupant(int socket) const
{
    if (socket < 0 || socket >= socketCount())
        throw std::out_of_range("socket " + std::to_string(socket) + " is out of range (" +
                                std::to_string(socketCount()) + " sockets)");
    for (size_t h = 0; h < m_hoses.size(); ++h) {
        const RunningHose& running = m_hoses[h];
        for (size_t k = 0; k < running.live.size(); ++k) {
            const LiveAttachment& a = running.live[k];
            if (a.attached && a.socket == socket)
                return {static_cast<int>(h), a.firstPoint == 0 ? 0 : 1, static_cast<int>(k)};
        }
    }
    return {};
}

PlugResult HoseRuntime::plug(int hose, int end, int socket, std::string* why)
{
    PlugResult out;
    const auto refuse = [&](std::string text) {
        if (why) *why = std::move(text);
        return out;
    };
    if (hose < 0 || hose >= hoseCount()) return refuse(hoseOutOfRangeText(hose, hoseCount()));
    if (socket < 0 || socket >= socketCount())
        return refuse("socket " + std::to_string(socket) + " is out of range: expected 0 to " +
                      std::to_string(socketCount() - 1) + " (" + std::to_string(socketCount()) +
                      " sockets)");
    if (end != 0 && end != 1) return refuse(badEndText(end));
    const RigHose& d = m_descriptor.hoses[static_cast<size_t>(hose)];
    const std::string name = runningHoseName(hose, d);
    if (d.isStatic) return refuse(name + " is static: its ends never plug");
    const RigSocket& s = m_descriptor.sockets[static_cast<size_t>(socket)];
    const std::string& plugTag = end == 0 ? d.plugStart : d.plugEnd;
    if (plugTag != s.tag)
        return refuse(
            "socket \"" + s.id + "\" takes plugs tagged \"" + s.tag + "\": end " +
            std::to_string(end) + " of " + name +
            (plugTag.empty() ? " has no plug" : " has a plug tagged \"" + plugTag + "\""));
    const SocketOccupant occupant = socketOccupant(socket);
    if (occupant.hose >= 0)
        return refuse("socket \"" + s.id + "\" holds end " + std::to_string(occupant.end) +
                      " of hose " + std::to_string(occupant.hose) + " (\"" +
                      m_descriptor.hoses[static_cast<size_t>(occupant.hose)].id +
                      "\") already: a socket holds one end at a time");
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    // Fixed where the end is now, on the socket's node; update() eases it in.
    const Frame start =
        (s.node >= 0 ? nodeWorldFrame(s.node) : Frame()).inverse() * endFrame(running, end);
    int attachment = -1;
    if (attachEnd(hose, end, s.node, start, &attachment, why).status == Status::InvalidInput)
        return out;
    LiveAttachment& live = running.live[static_cast<size_t>(attachment)];
    live.socket = socket;
    live.easingSeconds = kSnapSeconds;
    out.status = Status::Ok;
    out.socket = socket;
    out.end = end;
    out.attachment = attachment;
    out.easingSeconds = kSnapSeconds;
    return out;
}

PlugResult HoseRuntime::unplug(int hose, int end, std::string* why)
{
    PlugResult out;
    const auto refuse = [&](std::string text) {
        if (why) *why = std::move(text);
        return out;
    };
    if (hose < 0 || hose >= hoseCount()) return refuse(hoseOutOfRangeText(hose, hoseCount()));
    if (end != 0 && end != 1) return refuse(badEndText(end));
    const RigHose& d = m_descriptor.hoses[static_cast<size_t>(hose)];
    const std::string name = runningHoseName(hose, d);
    if (d.isStatic) return refuse(name + " is static: its ends never unplug");
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    const int attachment = attachmentAtEnd(running, end);
    if (attachment < 0)
        return refuse("end " + std::to_string(end) + " of " + name +
                      " is not plugged: no attachment fixes it");
    if (detachEnd(hose, attachment, why).status == Status::InvalidInput) return out;
    LiveAttachment& live = running.live[static_cast<size_t>(attachment)];
    live.easingSeconds = 0.0;
    out.status = Status::Ok;
    out.socket = live.socket;
    out.end = end;
    out.attachment = attachment;
    return out;
}

PlugResult HoseRuntime::release(int hose)
{
    PlugResult out;
    if (hose < 0 || hose >= hoseCount()) return out;
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    const RigHose& d = m_descriptor.hoses[static_cast<size_t>(hose)];
    const int held = running.hose.heldPoint();
    const int last = running.hose.pointCount() - 1;
    const int end = held == 0 ? 0 : held == last ? 1 : held == 1 ? 0 : held == last - 1 ? 1 : -1;
    running.hose.releaseGrab();
    running.pullsStale = true; // the held point no longer pins a span
    out.status = Status::Ok;
    const std::string& plugTag = end == 0 ? d.plugStart : d.plugEnd;
    if (end < 0 || d.isStatic || plugTag.empty() || attachmentAtEnd(running, end) >= 0) return out;
    // The nearest free socket that catches the end and takes its plug.
    const Frame tip = endFrame(running, end);
    const Vec3 outward = tip.rotation * Vec3::UnitZ();
    int caught = -1;
    double nearest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < socketCount(); ++k) {
        const SocketPose pose = socket(k);
        const double distance = (tip.translation - pose.position).norm();
        const double angle = std::acos(std::clamp(outward.dot(-pose.axis), -1.0, 1.0));
        if (pose.description->tag != plugTag || distance > pose.description->captureRadius ||
            angle > pose.description->captureAngle || distance >= nearest ||
            socketOccupant(k).hose >= 0)
            continue;
        caught = k;
        nearest = distance;
    }
    if (caught < 0) return out;
    const PlugResult plugged = plug(hose, end, caught);
    return plugged ? plugged : out;
}

void HoseRuntime::easeIntoSockets(size_t hose, double seconds)
{
    RunningHose& running = m_hoses[hose];
    for (LiveAttachment& a : running.live) {
        if (!a.attached || a.socket < 0 || a.easingSeconds <= 0.0) continue;
        const RigSocket& s = m_descriptor.sockets[static_cast<size_t>(a.socket)];
        // The end segment turned the shortest way onto −axis (its turn about the axis kept),
        // the end point onto the socket: of what is left, the share this frame's time is of the
        // easing time left, so the end goes at the same pace whatever the frame rate. Within a
        // rounding of the time left, this frame seats it (five frames of 1/90 s are kSnapSeconds).
        const Quat into =
            (Quat::FromTwoVectors(a.offset.rotation * Vec3::UnitZ(), -s.axis) * a.offset.rotation)
                .normalized();
        const bool last = a.easingSeconds <= seconds * (1.0 + 1e-9);
        const double share = last ? 1.0 : seconds / a.easingSeconds;
        a.offset.translation += share * (s.position - a.offset.translation);
        a.offset.rotation = a.offset.rotation.slerp(share, into).normalized();
        a.easingSeconds = last ? 0.0 : a.easingSeconds - seconds;
        const Frame target = (a.node >= 0 ? nodeWorldFrame(a.node) : Frame()) * a.offset;
        combine(running.pendingResult, running.hose.moveAttachment(a.id, target));
    }
}

namespace {
template <class T> std::vector<T> slice(const std::vector<T>& values, size_t from, size_t to)
{
    from = std::min(from, values.size());
    to = std::min(std::max(to, from), values.size());
    return std::vector<T>(values.begin() + static_cast<std::ptrdiff_t>(from),
                          values.begin() + static_cast<std::ptrdiff_t>(to));
}
} // namespace

CutResult HoseRuntime::cut(int hose, int point, std::string* why)
{
    CutResult out;
    const auto refuse = [&](std::string text) {
        if (why) *why = std::move(text);
        return out;
    };
    if (hose < 0 || hose >= hoseCount()) return refuse(hoseOutOfRangeText(hose, hoseCount()));
    const size_t h = static_cast<size_t>(hose);
    const RigHose d = m_descriptor.hoses[h]; // a copy: the list grows below
    const std::string name = runningHoseName(hose, d);
    if (d.isStatic) return refuse(name + " is static: it is never cut");
    const int n = m_hoses[h].hose.pointCount();
    if (point <= 0 || point >= n - 1)
        return refuse("point " + std::to_string(point) + " of " + name +
                      ": expected an interior point, 1 to " + std::to_string(n - 2) +
                      " (a cut at an end or beyond cuts nothing off)");
    std::optional<CutHose> pieces;
    try {
        pieces.emplace(cutHose(m_hoses[h].hose, point));
    } catch (const InvalidArgument& error) {
        return refuse(name + ": " + error.what());
    }
    // Where each Hose attachment id of the hose cut went: its piece and its id there.
    std::map<int, CutHose::Moved> moved;
    const std::vector<Hose::Attachment>& old = m_hoses[h].hose.attachments();
    for (size_t k = 0; k < old.size() && k < pieces->attachments.size(); ++k)
        moved[old[k].id] = pieces->attachments[k];

    const size_t p = static_cast<size_t>(point), count = static_cast<size_t>(n);
    double restBefore = 0.0; // rest arc length from point 0 to the cut
    for (size_t s = 0; s < p; ++s)
        restBefore += d.restLengths[s];
    RigHose descriptions[2] = {d, d};
    descriptions[0].plugEnd.clear(); // the cut ends carry no plug
    descriptions[1].plugStart.clear();
    HoseSurface beforeSurface(pieces->before), afterSurface(pieces->after);
    const std::uint64_t unposed = std::numeric_limits<std::uint64_t>::max();
    RunningHose runnings[2] = {{std::move(pieces->before),
                                std::move(beforeSurface),
                                {},
                                {},
                                {},
                                {},
                                {},
                                true,
                                unposed,
                                {},
                                m_hoses[h].pendingResult,
                                {},
                                {},
                                {},
                                {}},
                               {std::move(pieces->after),
                                std::move(afterSurface),
                                {},
                                {},
                                {},
                                {},
                                {},
                                true,
                                unposed,
                                {},
                                {},
                                {},
                                {},
                                {},
                                {}}};
    const size_t from[2] = {0, p}, until[2] = {p + 1, count};
    for (int piece = 0; piece < 2; ++piece) {
        RigHose& part = descriptions[piece];
        RunningHose& running = runnings[piece];
        const int shift = piece == 0 ? 0 : point;
        part.axis = running.hose.points();
        part.restLengths = slice(d.restLengths, from[piece], until[piece] - 1);
        // Interior joint j of the hose cut is entry j − 1; the piece's are from + 1 … until − 2.
        part.jointBendLimits = slice(d.jointBendLimits, from[piece], until[piece] - 2);
        part.jointMinBendRadii = slice(d.jointMinBendRadii, from[piece], until[piece] - 2);
        part.jointNodes = slice(d.jointNodes, from[piece], until[piece]);
        if (m_hoses[h].reelOutlet.clip != ReelOutlet::kNever) { // reeled: by where joints are
            const RunningHose& whole = m_hoses[h];
            const std::vector<double> arcs = restArcs(whole.hose);
            const auto [outlet, side] = outletPoint(whole, whole.reelOutlet, d);
            const double outletArc = outlet >= 0 ? arcs[static_cast<size_t>(outlet)] : std::nan("");
            part.jointNodes.clear();
            for (size_t j = 0; j < whole.jointArc.size(); ++j) {
                const double place = jointPlace(whole, j, arcs, outletArc, side);
                if ((place > restBefore) != (piece == 1)) continue;
                part.jointNodes.push_back(d.jointNodes[j]);
                running.jointArc.push_back(piece == 1 ? place - restBefore : place);
                running.jointBeyond.push_back(0);
            }
            running.reelOutlet.clip = ReelOutlet::kNone;
        } else if (piece == 1 && !part.jointNodes.empty()) {
            part.jointNodes.front() = -1;
        }
        part.attachments.clear();
        for (const LiveAttachment& a : m_hoses[h].live) {
            LiveAttachment kept = a;
            if (a.attached) {
                const CutHose::Moved& target = moved.at(a.id);
                if (target.piece != piece) continue;
                kept.id = target.id;
            } else if ((a.firstPoint >= point) != (piece == 1)) {
                continue;
            }
            kept.firstPoint -= shift;
            kept.lastPoint -= shift;
            running.live.push_back(kept);
            if (kept.attached) {
                RigAttachment described;
                described.node = kept.node;
                described.offset = kept.offset;
                described.frame =
                    (kept.node >= 0 ? nodeWorldFrame(kept.node) : Frame()) * kept.offset;
                described.firstPoint = kept.firstPoint;
                described.lastPoint = kept.lastPoint;
                part.attachments.push_back(described);
            }
        }
        part.clips.clear();
        for (size_t c = 0; c < d.clips.size(); ++c) {
            const CutHose::Moved& target = moved.at(m_hoses[h].clipIds[c]);
            if (target.piece != piece) continue;
            RigClip clip = d.clips[c];
            if (piece == 1) {
                clip.place -= restBefore;
                clip.slideMin = std::max(0.0, clip.slideMin - restBefore);
                clip.slideMax -= restBefore;
            }
            part.clips.push_back(clip);
            running.clipIds.push_back(target.id);
        }
        findGrabbable(running, part);
        part.grabbablePoints = running.grabbable;
        for (int joint : part.jointNodes)
            running.jointParents.push_back(joint >= 0 ? m_nodes[static_cast<size_t>(joint)].parent
                                                      : -1);
    }
    std::string id = d.id + "~" + std::to_string(m_hoses.size());
    while (findHose(id) >= 0)
        id += "~";
    descriptions[1].id = id;
    descriptions[1].name = d.name + " (cut)";

    m_descriptor.hoses[h] = std::move(descriptions[0]);
    m_descriptor.hoses.push_back(std::move(descriptions[1]));
    m_hoses[h] = std::move(runnings[0]);
    m_hoses.push_back(std::move(runnings[1]));
    m_hoses[h].hose.setBudget(m_budget);
    m_hoses.back().hose.setBudget(m_budget);
    out.newHose = hoseCount() - 1;
    for (const size_t piece : {h, static_cast<size_t>(out.newHose)}) {
        m_hoses[piece].hose.setColliders({});
        if (!m_colliders.empty()) chooseColliders(piece);
    }
    refresh();
    out.status = Status::Ok;
    return out;
}

const Hose::Attachment& HoseRuntime::clip(int hose, int clip) const
{
    const RunningHose& running = m_hoses.at(static_cast<size_t>(hose));
    const RigHose& d = m_descriptor.hoses.at(static_cast<size_t>(hose));
    if (clip < 0 || static_cast<size_t>(clip) >= d.clips.size())
        throw std::out_of_range("hose " + std::to_string(hose) + ": clip " + std::to_string(clip) +
                                " is out of range");
    // A clip is never detached at run time.
    const int id = running.clipIds.at(static_cast<size_t>(clip));
    for (const Hose::Attachment& attachment : running.hose.attachments())
        if (attachment.id == id) return attachment;
    throw std::logic_error("hose " + std::to_string(hose) + ": clip " + std::to_string(clip) +
                           " (id " + std::to_string(id) + ") is not on the hose");
}

HoseRuntime::SocketPose HoseRuntime::socket(int index) const
{
    if (index < 0 || index >= socketCount())
        throw std::out_of_range("socket " + std::to_string(index) + " is out of range (" +
                                std::to_string(socketCount()) + " sockets)");
    const RigSocket& description = m_descriptor.sockets[static_cast<size_t>(index)];
    const Frame frame = description.node >= 0 ? nodeWorldFrame(description.node) : Frame{};
    return {&description, frame.apply(description.position),
            (frame.rotation * description.axis).normalized()};
}

int HoseRuntime::findSocket(std::string_view id) const
{
    for (size_t k = 0; k < m_descriptor.sockets.size(); ++k)
        if (m_descriptor.sockets[k].id == id) return static_cast<int>(k);
    return -1;
}

int HoseRuntime::findHose(std::string_view id) const
{
    for (size_t h = 0; h < m_descriptor.hoses.size(); ++h)
        if (m_descriptor.hoses[h].id == id) return static_cast<int>(h);
    return -1;
}

int HoseRuntime::findNode(std::string_view name) const
{
    for (size_t i = 0; i < m_nodes.size(); ++i)
        if (m_nodes[i].name == name) return static_cast<int>(i);
    return -1;
}

Frame HoseRuntime::nodeWorldFrame(int node) const
{
    return rigidPart(m_world.at(static_cast<size_t>(node)));
}

void HoseRuntime::recomputeWorld()
{
    m_world.assign(m_nodes.size(), Eigen::Matrix4d::Identity());
    std::vector<char> done(m_nodes.size(), 0);
    // Nodes may list parents after children: resolve each chain once, memoised.
    std::vector<int> chain;
    for (size_t i = 0; i < m_nodes.size(); ++i) {
        chain.clear();
        for (int n = static_cast<int>(i); n >= 0 && !done[static_cast<size_t>(n)];
             n = m_nodes[static_cast<size_t>(n)].parent)
            chain.push_back(n);
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const RigNode& node = m_nodes[static_cast<size_t>(*it)];
            const detail::Affine local = detail::matrixOf(node.local);
            m_world[static_cast<size_t>(*it)] =
                node.parent >= 0 ? detail::Affine(m_world[static_cast<size_t>(node.parent)] * local)
                                 : local;
            done[static_cast<size_t>(*it)] = 1;
        }
    }
}

std::vector<HoseUpdate> HoseRuntime::setNodeTransform(int node, const NodeTransform& local)
{
    if (node < 0 || node >= nodeCount() || !finite(local)) {
        HoseUpdate rejected;
        rejected.result.status = Status::InvalidInput;
        return {rejected};
    }
    NodeTransform normalized = local;
    normalized.rotation.normalize();
    const NodeTransform& current = m_nodes[static_cast<size_t>(node)].local;
    // The transform the node has (a still part sent every frame): nothing moves, so nothing is
    // solved again and a gravity hose's rest rule keeps counting.
    if (normalized.translation == current.translation &&
        normalized.rotation.coeffs() == current.rotation.coeffs() &&
        normalized.scale == current.scale)
        return {};
    m_nodes[static_cast<size_t>(node)].local = normalized;
    recomputeWorld();
    m_nodesMoved = true;
    const auto isUnder = [&](int candidate) {
        for (int n = candidate; n >= 0; n = m_nodes[static_cast<size_t>(n)].parent)
            if (n == node) return true;
        return false;
    };
    std::vector<const MeshCollider*> movedColliders;
    for (size_t c = 0; c < m_colliders.size(); ++c)
        if (isUnder(m_descriptor.colliders[c])) {
            m_colliders[c]->setFrame(nodeWorldFrame(m_descriptor.colliders[c]));
            movedColliders.push_back(m_colliders[c].get());
        }
    std::vector<HoseUpdate> updates;
    for (size_t h = 0; h < m_hoses.size(); ++h) {
        const RigHose& d = m_descriptor.hoses[h];
        std::vector<int> ids;
        std::vector<Frame> frames;
        for (const LiveAttachment& a : m_hoses[h].live)
            if (a.attached && a.node >= 0 && isUnder(a.node)) {
                ids.push_back(a.id);
                frames.push_back(nodeWorldFrame(a.node) * a.offset);
            }
        for (size_t k = 0; k < d.clips.size(); ++k)
            if (d.clips[k].node >= 0 && isUnder(d.clips[k].node)) {
                ids.push_back(m_hoses[h].clipIds[k]);
                frames.push_back(nodeWorldFrame(d.clips[k].node) * d.clips[k].offset);
            }
        if (ids.empty()) {
            bool nearMovedCollider = false;
            for (const auto& collider : m_hoses[h].hose.colliders())
                nearMovedCollider =
                    nearMovedCollider || std::find(movedColliders.begin(), movedColliders.end(),
                                                   collider.get()) != movedColliders.end();
            if (nearMovedCollider)
                updates.push_back({static_cast<int>(h), m_hoses[h].hose.resolveCollisions()});
            continue;
        }
        HoseUpdate update;
        update.hose = static_cast<int>(h);
        update.result = ids.size() == 1 ? m_hoses[h].hose.moveAttachment(ids[0], frames[0])
                                        : m_hoses[h].hose.moveAttachments(ids, frames);
        updates.push_back(update);
    }
    for (const HoseUpdate& update : updates)
        combine(m_hoses[static_cast<size_t>(update.hose)].pendingResult, update.result);
    return updates;
}

UpdateResult HoseRuntime::grab(int hose, int point, const Vec3& target)
{
    UpdateResult rejected;
    rejected.status = Status::InvalidInput;
    if (hose < 0 || hose >= hoseCount()) return rejected;
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    const std::vector<int>& grabbable = running.grabbable;
    if (!std::binary_search(grabbable.begin(), grabbable.end(), point)) return rejected;
    const UpdateResult result = running.hose.grab(point, target);
    combine(running.pendingResult, result);
    return result;
}

int HoseRuntime::update()
{
    return update(Gravity::kFrameSeconds);
}

int HoseRuntime::update(double seconds)
{
    if (!std::isfinite(seconds) || !(seconds > 0.0) || seconds > Gravity::kMaxFrameSeconds) {
        std::ostringstream text;
        text << "seconds: expected the frame's time in (0, " << Gravity::kMaxFrameSeconds
             << "] s, got " << seconds;
        throw InvalidArgument(text.str());
    }
    for (size_t h = 0; h < m_hoses.size(); ++h) {
        RunningHose& running = m_hoses[h];
        easeIntoSockets(h, seconds);
        // Gravity, and work a budget left pending (Hose::step() goes on with it within the
        // budget; what no budgeted try advances gives way or rests in the library, so no frame
        // costs more than the budget).
        if (m_descriptor.hoses[h].gravity.enabled || running.hose.pending())
            combine(running.pendingResult, running.hose.step(seconds));
        running.frameResult = running.pendingResult;
        // Under a budget: what the frame left pending (the hose's, whichever call left it).
        running.frameResult.pending = running.hose.pending();
        running.frameResult.remaining = running.hose.remaining();
        running.pendingResult = UpdateResult();
    }
    return refresh();
}

void HoseRuntime::setBudget(const UpdateBudget& budget)
{
    if (budget.newtonSteps < 0)
        throw InvalidArgument("budget.newtonSteps: expected a number of steps >= 0 (0: no bound), "
                              "got " +
                              std::to_string(budget.newtonSteps));
    m_budget = budget;
    for (RunningHose& running : m_hoses)
        running.hose.setBudget(budget);
}

bool HoseRuntime::pending(int hose) const
{
    return hose >= 0 && hose < hoseCount() && m_hoses[static_cast<size_t>(hose)].hose.pending();
}

double HoseRuntime::remaining(int hose) const
{
    return pending(hose) ? m_hoses[static_cast<size_t>(hose)].hose.remaining() : 0.0;
}

void HoseRuntime::combine(UpdateResult& frame, const UpdateResult& result)
{
    if (result.status == Status::InvalidInput) return; // rejected: nothing changed
    const auto rank = [](Status status) {
        switch (status) { // no default: a new status must be ranked here
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
    };
    if (rank(result.status) > rank(frame.status)) frame.status = result.status;
    frame.lengthViolation = std::max(frame.lengthViolation, result.lengthViolation);
    frame.angleViolation = std::max(frame.angleViolation, result.angleViolation);
    frame.grabError = std::max(frame.grabError, result.grabError);
    frame.movedPoints += result.movedPoints;
    frame.blocked = frame.blocked || result.blocked;
    frame.penetration = std::max(frame.penetration, result.penetration);
    frame.contacts = std::max(frame.contacts, result.contacts);
    frame.iterations += result.iterations;
}

int HoseRuntime::refresh()
{
    int recomputed = 0;
    for (size_t h = 0; h < m_hoses.size(); ++h) {
        RunningHose& running = m_hoses[h];
        const bool changed = running.surface.update(running.hose);
        const bool reshaped = changed || running.posedRevision != running.hose.revision();
        if (reshaped || m_nodesMoved) {
            poseJoints(running, m_descriptor.hoses[h]);
            running.posedRevision = running.hose.revision();
            ++recomputed;
        }
        if (reshaped || running.pullsStale) {
            measurePulls(running);
            running.pullsStale = false;
        }
    }
    m_nodesMoved = false;
    return recomputed;
}

void HoseRuntime::poseJoints(RunningHose& running, const RigHose& description)
{
    if (description.isStatic) { // a plain mesh, carried by its node: no joints to pose
        running.poses.clear();
        return;
    }
    const std::vector<RingFrame>& frames = running.surface.frames();
    const Vec3& origin = running.hose.origin();
    // A reeled hose's joints sit at rest arc lengths (reel()), between two rings: the centre
    // interpolated, the rotation slerped; otherwise joint i is ring i.
    const bool byArc = running.reelOutlet.clip != ReelOutlet::kNever && frames.size() >= 2;
    std::vector<double> arcs;
    double outletArc = std::nan("");
    int side = 1;
    if (byArc) {
        arcs = restArcs(running.hose);
        const auto [outlet, outletSide] = outletPoint(running, running.reelOutlet, description);
        if (outlet >= 0) outletArc = arcs[static_cast<size_t>(outlet)];
        side = outletSide;
    }
    running.poses.resize(byArc ? running.jointArc.size() : frames.size());
    // The joints share their parent node as a rule: its inverse is worked out once. A parent
    // whose world transform is a rotation and a uniform positive scale to kSimilar (relative;
    // scenes stored in floats carry scales that differ in the eighth digit) gives each joint's
    // local pose by quaternion products; any other (shear, a non-uniform scale, a reflection)
    // goes through the matrix and its decomposition.
    int invertedParent = -1;
    bool similarity = false;
    detail::Affine parentInverse;
    NodeTransform parent;
    Quat parentRotationInverse = Quat::Identity();
    double inverseScale = 1.0;
    for (size_t i = 0; i < running.poses.size(); ++i) {
        JointPose& pose = running.poses[i];
        pose.node = i < description.jointNodes.size() ? description.jointNodes[i] : -1;
        if (byArc) {
            const double place = jointPlace(running, i, arcs, outletArc, side);
            const size_t k = std::min<size_t>(
                static_cast<size_t>(std::upper_bound(arcs.begin(), arcs.end(), place) -
                                    arcs.begin()) -
                    1,
                arcs.size() - 2);
            const double t = std::clamp((place - arcs[k]) / (arcs[k + 1] - arcs[k]), 0.0, 1.0);
            pose.world.translation =
                origin + (1.0 - t) * frames[k].center + t * frames[k + 1].center;
            pose.world.rotation = frames[k].rotation().slerp(t, frames[k + 1].rotation());
        } else {
            pose.world.translation = origin + frames[i].center;
            pose.world.rotation = frames[i].rotation();
        }
        const int parentNode = i < running.jointParents.size() ? running.jointParents[i] : -1;
        if (parentNode < 0) {
            pose.local.translation = pose.world.translation;
            pose.local.rotation = pose.world.rotation;
            pose.local.scale = Vec3::Ones();
            continue;
        }
        if (parentNode != invertedParent) {
            const detail::Affine& world = m_world[static_cast<size_t>(parentNode)];
            const bool noShear = detail::decompose(world, parent, kSimilar);
            const double scale = parent.scale.mean();
            similarity = noShear && (parent.scale.array() > 0.0).all() &&
                         (parent.scale.array() - scale).abs().maxCoeff() <= kSimilar * scale;
            if (similarity) {
                parentRotationInverse = parent.rotation.conjugate();
                inverseScale = 1.0 / scale;
            } else {
                parentInverse = world.inverse();
            }
            invertedParent = parentNode;
        }
        if (similarity) {
            pose.local.translation = parentRotationInverse *
                                     (pose.world.translation - parent.translation) * inverseScale;
            pose.local.rotation = (parentRotationInverse * pose.world.rotation).normalized();
            if (pose.local.rotation.w() < 0.0) // of a rotation's two quaternions, w ≥ 0
                pose.local.rotation.coeffs() = -pose.local.rotation.coeffs();
            pose.local.scale = Vec3::Constant(inverseScale);
            continue;
        }
        const detail::Affine local = parentInverse * detail::matrixOf(pose.world);
        detail::decompose(local, pose.local);
    }
}

void HoseRuntime::measurePulls(RunningHose& running)
{
    running.pulls.resize(running.live.size());
    for (size_t k = 0; k < running.live.size(); ++k)
        running.pulls[k] = running.live[k].attached
                               ? chaintube::attachmentPull(running.hose, running.live[k].id)
                               : AttachmentPull();
}

int HoseRuntime::attachmentCount(int hose) const
{
    if (hose < 0 || hose >= hoseCount()) return 0;
    return static_cast<int>(m_hoses[static_cast<size_t>(hose)].live.size());
}

const AttachmentPull& HoseRuntime::attachmentPull(int hose, int attachment) const
{
    const RunningHose& running = m_hoses.at(static_cast<size_t>(hose));
    if (attachment < 0 || static_cast<size_t>(attachment) >= running.live.size())
        throw std::out_of_range("hose " + std::to_string(hose) + ": attachment " +
                                std::to_string(attachment) + " is out of range");
    static const AttachmentPull unmeasured; // attached since the last update()
    return static_cast<size_t>(attachment) < running.pulls.size()
               ? running.pulls[static_cast<size_t>(attachment)]
               : unmeasured;
}

std::vector<float> HoseRuntime::worldPositions(int hose) const
{
    const RunningHose& running = m_hoses.at(static_cast<size_t>(hose));
    const std::span<const float> local = running.surface.positions();
    const Vec3& origin = running.hose.origin();
    std::vector<float> world(local.size());
    for (size_t v = 0; v < local.size(); v += 3)
        for (size_t c = 0; c < 3; ++c)
            world[v + c] = static_cast<float>(static_cast<double>(local[v + c]) +
                                              origin(static_cast<Eigen::Index>(c)));
    return world;
}

} // namespace chaintube::rig
