#include "chaintube/export/runtime.h"

#include "chaintube/formats/collider_exemption.h"
#include "gltf_container.h"
#include "transform_math.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace chaintube::rig {

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
        RunningHose running{
            std::move(hose), std::move(surface), std::move(attachmentIds), {}, 0, {}, {}, {}};
        for (int joint : d.jointNodes)
            running.jointParents.push_back(runtime.m_nodes[static_cast<size_t>(joint)].parent);
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
    // Every hose stays outside the colliders except the nodes it is attached to and their
    // ancestors (its ends sit in those: formats/collider_exemption.h, the clearance check's rule).
    const auto parentOf = [&](int n) { return runtime.m_nodes[static_cast<size_t>(n)].parent; };
    for (size_t h = 0; h < runtime.m_hoses.size() && !runtime.m_colliders.empty(); ++h) {
        const RigHose& d = runtime.m_descriptor.hoses[h];
        std::vector<std::shared_ptr<const MeshCollider>> used;
        for (size_t c = 0; c < runtime.m_colliders.size(); ++c)
            if (std::none_of(d.attachments.begin(), d.attachments.end(),
                             [&](const RigAttachment& a) {
                                 return formats::attachmentExempts(
                                     a.node, runtime.m_descriptor.colliders[c], parentOf);
                             }) &&
                std::none_of(d.clips.begin(), d.clips.end(), [&](const RigClip& a) {
                    return formats::attachmentExempts(a.node, runtime.m_descriptor.colliders[c],
                                                      parentOf);
                }))
                used.push_back(runtime.m_colliders[c]);
        if (!used.empty()) runtime.m_hoses[h].hose.setColliders(std::move(used));
    }
    // A gravity hose is exported as it hangs (formats::settleUnderGravity): it starts at rest and
    // falls again once an input moves it, instead of re-settling (creeping) from the file.
    for (RunningHose& running : runtime.m_hoses)
        if (running.hose.spec().gravity.enabled) running.hose.markSettled();
    runtime.refresh(); // surfaces and poses as exported
    return runtime;
}

const Hose::Attachment& HoseRuntime::clip(int hose, int clip) const
{
    const RunningHose& running = m_hoses.at(static_cast<size_t>(hose));
    const RigHose& d = m_descriptor.hoses.at(static_cast<size_t>(hose));
    if (clip < 0 || static_cast<size_t>(clip) >= d.clips.size())
        throw std::out_of_range("hose " + std::to_string(hose) + ": clip " + std::to_string(clip) +
                                " is out of range");
    // Ids after the attachments' (rebuildHose); a clip is never detached at run time.
    const int id = running.attachmentIds.at(d.attachments.size() + static_cast<size_t>(clip));
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
    m_nodes[static_cast<size_t>(node)].local = local;
    m_nodes[static_cast<size_t>(node)].local.rotation.normalize();
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
        for (size_t k = 0; k < d.attachments.size(); ++k)
            if (d.attachments[k].node >= 0 && isUnder(d.attachments[k].node)) {
                ids.push_back(m_hoses[h].attachmentIds[k]);
                frames.push_back(nodeWorldFrame(d.attachments[k].node) * d.attachments[k].offset);
            }
        for (size_t k = 0; k < d.clips.size(); ++k) // ids after the attachments' (rebuildHose)
            if (d.clips[k].node >= 0 && isUnder(d.clips[k].node)) {
                ids.push_back(m_hoses[h].attachmentIds[d.attachments.size() + k]);
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
    const std::vector<int>& grabbable =
        m_descriptor.hoses[static_cast<size_t>(hose)].grabbablePoints;
    if (!std::binary_search(grabbable.begin(), grabbable.end(), point)) return rejected;
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    const UpdateResult result = running.hose.grab(point, target);
    combine(running.pendingResult, result);
    return result;
}

bool HoseRuntime::release(int hose)
{
    if (hose < 0 || hose >= hoseCount()) return false;
    m_hoses[static_cast<size_t>(hose)].hose.releaseGrab();
    return true;
}

int HoseRuntime::update()
{
    for (size_t h = 0; h < m_hoses.size(); ++h) {
        RunningHose& running = m_hoses[h];
        if (m_descriptor.hoses[h].gravity.enabled)
            combine(running.pendingResult, running.hose.step());
        running.frameResult = running.pendingResult;
        running.pendingResult = UpdateResult();
    }
    return refresh();
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
}

int HoseRuntime::refresh()
{
    int recomputed = 0;
    for (size_t h = 0; h < m_hoses.size(); ++h) {
        RunningHose& running = m_hoses[h];
        const bool changed = running.surface.update(running.hose);
        if (changed || m_nodesMoved || running.posedRevision != running.hose.revision()) {
            poseJoints(running, m_descriptor.hoses[h]);
            running.posedRevision = running.hose.revision();
            ++recomputed;
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
    running.poses.resize(frames.size());
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
    for (size_t i = 0; i < frames.size(); ++i) {
        JointPose& pose = running.poses[i];
        pose.node = i < description.jointNodes.size() ? description.jointNodes[i] : -1;
        pose.world.translation = origin + frames[i].center;
        pose.world.rotation = frames[i].rotation();
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
