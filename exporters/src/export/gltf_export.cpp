#include "chaintube/export/gltf_export.h"

#include "../runtime/transform_math.h"
#include "chaintube/formats/atomic_file.h"
#include "chaintube/formats/errors.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/metrics.h"
#include "chaintube/surface.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <tiny_gltf.h>

namespace chaintube::exporting {

namespace {

namespace fs = std::filesystem;
using rig::detail::Affine;

constexpr int kArrayBuffer = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElementArrayBuffer = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;

Affine affineOf(const formats::Mat4& m)
{
    return Affine(m);
}

std::vector<double> toVector(const Vec3& v)
{
    return {v.x(), v.y(), v.z()};
}

/// Accumulates buffer 0 and the accessors that view it.
class BufferWriter
{
public:
    explicit BufferWriter(tinygltf::Model& model) : m_model(model) {}

    int view(const void* data, size_t bytes, int target)
    {
        while (m_bytes.size() % 4)
            m_bytes.push_back(0);
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = m_bytes.size();
        view.byteLength = bytes;
        view.target = target;
        const auto* begin = static_cast<const unsigned char*>(data);
        m_bytes.insert(m_bytes.end(), begin, begin + bytes);
        m_model.bufferViews.push_back(view);
        return static_cast<int>(m_model.bufferViews.size()) - 1;
    }

    int accessor(int view, int componentType, size_t count, int type, std::vector<double> min = {},
                 std::vector<double> max = {})
    {
        tinygltf::Accessor accessor;
        accessor.bufferView = view;
        accessor.componentType = componentType;
        accessor.count = count;
        accessor.type = type;
        accessor.minValues = std::move(min);
        accessor.maxValues = std::move(max);
        m_model.accessors.push_back(accessor);
        return static_cast<int>(m_model.accessors.size()) - 1;
    }

    int vec3Floats(const std::vector<float>& values, bool withBounds)
    {
        std::vector<double> low, high;
        if (withBounds) {
            low.assign(3, std::numeric_limits<double>::infinity());
            high.assign(3, -std::numeric_limits<double>::infinity());
            for (size_t i = 0; i < values.size(); ++i) {
                low[i % 3] = std::min(low[i % 3], static_cast<double>(values[i]));
                high[i % 3] = std::max(high[i % 3], static_cast<double>(values[i]));
            }
        }
        const int v = view(values.data(), values.size() * sizeof(float), kArrayBuffer);
        return accessor(v, TINYGLTF_COMPONENT_TYPE_FLOAT, values.size() / 3, TINYGLTF_TYPE_VEC3,
                        low, high);
    }

    int indices(const std::vector<std::uint32_t>& values, size_t vertexCount)
    {
        if (vertexCount <= 65535) {
            std::vector<std::uint16_t> narrow(values.begin(), values.end());
            const int v = view(narrow.data(), narrow.size() * 2, kElementArrayBuffer);
            return accessor(v, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, values.size(),
                            TINYGLTF_TYPE_SCALAR);
        }
        const int v = view(values.data(), values.size() * 4, kElementArrayBuffer);
        return accessor(v, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, values.size(),
                        TINYGLTF_TYPE_SCALAR);
    }

    std::vector<unsigned char>& bytes() { return m_bytes; }

private:
    tinygltf::Model& m_model;
    std::vector<unsigned char> m_bytes;
};

/// Sets a node's transform as TRS when the matrix is one (always for joints), else `matrix`.
void setTransform(tinygltf::Node& node, const Affine& local, bool allowMatrix,
                  const std::string& what)
{
    rig::NodeTransform trs;
    if (!rig::detail::decompose(local, trs)) {
        if (!allowMatrix)
            throw InvalidArgument(what + ": its parent's world transform has shear, so the joint "
                                         "cannot be expressed as a glTF TRS node");
        node.matrix.assign(local.data(), local.data() + 16); // column-major, as glTF
        return;
    }
    if (trs.translation.norm() > 0) node.translation = toVector(trs.translation);
    if (!trs.rotation.coeffs().isApprox(Quat::Identity().coeffs(), 0.0))
        node.rotation = {trs.rotation.x(), trs.rotation.y(), trs.rotation.z(), trs.rotation.w()};
    if ((trs.scale - Vec3::Ones()).cwiseAbs().maxCoeff() > 1e-12) node.scale = toVector(trs.scale);
}

/// Unit normals (a zero or non-finite normal gets the triangle-free default +Y: the validator
/// rejects non-unit normals, and CAD tessellations sometimes carry degenerate ones).
std::vector<float> unitNormals(const std::vector<float>& normals)
{
    std::vector<float> result(normals.size());
    for (size_t v = 0; v + 2 < normals.size(); v += 3) {
        const Eigen::Vector3d n(normals[v], normals[v + 1], normals[v + 2]);
        const double length = n.norm();
        const Eigen::Vector3d unit = (std::isfinite(length) && length > 1e-12)
                                         ? Eigen::Vector3d(n / length)
                                         : Eigen::Vector3d::UnitY();
        for (int c = 0; c < 3; ++c)
            result[v + static_cast<size_t>(c)] = static_cast<float>(unit(c));
    }
    return result;
}

struct SceneMeshAccessors
{
    bool empty = true;
    int position = -1, normal = -1, indices = -1;
};

SceneMeshAccessors writeSceneMesh(BufferWriter& buffer, const formats::SceneMesh& mesh)
{
    SceneMeshAccessors result;
    std::vector<std::uint32_t> triangles;
    triangles.reserve(mesh.indices.size());
    const size_t vertices = mesh.vertexCount();
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        if (a == b || b == c || a == c || a >= vertices || b >= vertices || c >= vertices)
            continue; // degenerate or broken triangles carry no surface
        triangles.insert(triangles.end(), {a, b, c});
    }
    if (triangles.empty() || vertices == 0) return result;
    result.empty = false;
    result.position = buffer.vec3Floats(mesh.positions, true);
    if (mesh.normals.size() == mesh.positions.size())
        result.normal = buffer.vec3Floats(unitNormals(mesh.normals), false);
    result.indices = buffer.indices(triangles, vertices);
    return result;
}

/// The GLB container around a JSON text and a binary chunk.
std::string glbBytes(std::string json, const std::vector<unsigned char>& bin)
{
    while (json.size() % 4)
        json.push_back(' ');
    std::string binary(bin.begin(), bin.end());
    while (binary.size() % 4)
        binary.push_back('\0');
    const auto u32 = [](std::uint32_t value) {
        std::string bytes(4, '\0');
        std::memcpy(bytes.data(), &value, 4);
        return bytes;
    };
    const size_t total = 12 + 8 + json.size() + (binary.empty() ? 0 : 8 + binary.size());
    std::string out = "glTF" + u32(2) + u32(static_cast<std::uint32_t>(total));
    out += u32(static_cast<std::uint32_t>(json.size())) + u32(0x4E4F534Au) + json;
    if (!binary.empty())
        out += u32(static_cast<std::uint32_t>(binary.size())) + u32(0x004E4942u) + binary;
    return out;
}

void reportProgress(const ExportOptions& options, double fraction, const fs::path& output)
{
    if (options.progress && !options.progress(fraction)) throw formats::Cancelled(output);
}

} // namespace

std::vector<std::string> hoseWarnings(const Hose& hose, const std::string& label)
{
    std::vector<std::string> warnings;
    const HoseMetrics m = measure(hose);
    if (m.overstretched())
        warnings.push_back(
            label + ": overstretched: segment " + std::to_string(m.lengthViolationSegment) +
            " is " + std::to_string(100.0 * m.lengthViolation) + " % beyond its stretch band");
    if (m.angleViolation > 1e-9)
        warnings.push_back(label + ": joint " + std::to_string(m.angleViolationJoint) + " bends " +
                           std::to_string(m.angleViolation) + " rad beyond its deflection limit");
    if (!m.bendBelowMinimum.empty())
        warnings.push_back(label + ": " + std::to_string(m.bendBelowMinimum.size()) +
                           " joint(s) bend below the minimum bend radius (smallest " +
                           std::to_string(m.smallestBendRadius) + " m at joint " +
                           std::to_string(m.smallestBendRadiusJoint) + ")");
    if (!m.selfIntersectingSegments.empty())
        warnings.push_back(label + ": rings self-intersect on the inside of the bend at " +
                           std::to_string(m.selfIntersectingSegments.size()) +
                           " segment(s) (worst overlap ratio " +
                           std::to_string(m.worstRingOverlap) + " at segment " +
                           std::to_string(m.worstRingOverlapSegment) + ")");
    return warnings;
}

ExportReport exportRig(const std::vector<const formats::ImportedScene*>& scenes,
                       const std::vector<ExportHose>& hoses, const std::string& rootName,
                       const fs::path& output, const ExportOptions& options)
{
    const auto started = std::chrono::steady_clock::now();
    Container container = options.container;
    if (container == Container::FromExtension) {
        const std::string extension = output.extension().string();
        if (extension == ".glb")
            container = Container::Glb;
        else if (extension == ".gltf")
            container = Container::Gltf;
        else
            throw InvalidArgument("export output '" + output.string() +
                                  "': expected a file name ending in .glb or .gltf");
    }
    for (size_t h = 0; h < hoses.size(); ++h) {
        const ExportHose& hose = hoses[h];
        const std::string label = "hoses[" + std::to_string(h) + "] '" + hose.id + "'";
        if (hose.attachedNodes.size() != hose.hose.attachments().size())
            throw InvalidArgument(label + ".attachedNodes: expected one per attachment (" +
                                  std::to_string(hose.hose.attachments().size()) + "), got " +
                                  std::to_string(hose.attachedNodes.size()));
        for (const NodeRef& ref : hose.attachedNodes)
            if (ref.scene >= 0 &&
                (ref.scene >= static_cast<int>(scenes.size()) ||
                 !scenes[static_cast<size_t>(ref.scene)] || ref.node < 0 ||
                 ref.node >=
                     static_cast<int>(scenes[static_cast<size_t>(ref.scene)]->nodes.size())))
                throw InvalidArgument(label + ".attachedNodes: scene " + std::to_string(ref.scene) +
                                      " node " + std::to_string(ref.node) + " does not exist");
    }

    for (size_t c = 0; c < options.colliders.size(); ++c) {
        const NodeRef& ref = options.colliders[c];
        const std::string label = "colliders[" + std::to_string(c) + "]";
        if (ref.scene < 0 || ref.scene >= static_cast<int>(scenes.size()) ||
            !scenes[static_cast<size_t>(ref.scene)] || ref.node < 0 ||
            ref.node >= static_cast<int>(scenes[static_cast<size_t>(ref.scene)]->nodes.size()))
            throw InvalidArgument(label + ": scene " + std::to_string(ref.scene) + " node " +
                                  std::to_string(ref.node) + " does not exist");
        const formats::ImportedScene& scene = *scenes[static_cast<size_t>(ref.scene)];
        bool triangles = false;
        for (int m : scene.nodes[static_cast<size_t>(ref.node)].meshes)
            triangles = triangles || scene.meshes[static_cast<size_t>(m)].indices.size() >= 3;
        if (!triangles)
            throw InvalidArgument(label + ": node '" +
                                  scene.nodes[static_cast<size_t>(ref.node)].path +
                                  "' has no mesh with triangles to collide with");
    }

    ExportReport report;
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = options.generator;
    model.extensionsUsed = {rig::kExtensionName};
    model.buffers.emplace_back();
    BufferWriter buffer(model);

    // The single root: every joint descends from it (glTF requires joints to share a root).
    model.nodes.emplace_back();
    model.nodes[0].name = rootName.empty() ? "ChainTube" : rootName;
    tinygltf::Scene gltfScene;
    gltfScene.name = model.nodes[0].name;
    gltfScene.nodes.push_back(0);

    // Scenes: nodes in their order (parents first), meshes as glTF meshes.
    std::vector<std::vector<int>> gltfNodeOf(scenes.size());
    for (size_t s = 0; s < scenes.size(); ++s) {
        if (!scenes[s]) continue;
        const formats::ImportedScene& scene = *scenes[s];
        // Collider nodes keep their meshes even without the scene's meshes (a runtime builds
        // its colliders from them).
        std::vector<char> isCollider(scene.nodes.size(), 0);
        std::vector<char> meshWanted(scene.meshes.size(), options.includeSceneMeshes ? 1 : 0);
        for (const NodeRef& ref : options.colliders)
            if (ref.scene == static_cast<int>(s)) {
                isCollider[static_cast<size_t>(ref.node)] = 1;
                for (int m : scene.nodes[static_cast<size_t>(ref.node)].meshes)
                    meshWanted[static_cast<size_t>(m)] = 1;
            }
        std::vector<SceneMeshAccessors> meshAccessors(scene.meshes.size());
        for (size_t m = 0; m < scene.meshes.size(); ++m)
            if (meshWanted[m]) meshAccessors[m] = writeSceneMesh(buffer, scene.meshes[m]);
        const auto exportsMesh = [&](size_t node, int m) {
            return (options.includeSceneMeshes || isCollider[node]) &&
                   !meshAccessors[static_cast<size_t>(m)].empty;
        };
        std::map<std::vector<int>, int> gltfMeshOf;
        // Empty leaves (no exported mesh, no kept child, no hose attached) carry nothing and
        // make the validator report NODE_EMPTY: they are left out unless asked for.
        std::vector<char> keep(scene.nodes.size(), options.keepEmptyNodes ? 1 : 0);
        for (const ExportHose& hose : hoses)
            for (const NodeRef& ref : hose.attachedNodes)
                if (ref.scene == static_cast<int>(s)) keep[static_cast<size_t>(ref.node)] = 1;
        for (size_t i = scene.nodes.size(); i-- > 0;) {
            const formats::SceneNode& source = scene.nodes[i];
            if (source.parent < 0) keep[i] = 1;
            for (int m : source.meshes)
                if (exportsMesh(i, m)) keep[i] = 1;
            if (keep[i] && source.parent >= 0) keep[static_cast<size_t>(source.parent)] = 1;
        }
        gltfNodeOf[s].assign(scene.nodes.size(), -1);
        for (size_t i = 0; i < scene.nodes.size(); ++i) {
            if (!keep[i]) continue;
            gltfNodeOf[s][i] = static_cast<int>(model.nodes.size());
            model.nodes.emplace_back();
        }
        for (size_t i = 0; i < scene.nodes.size(); ++i) {
            if (!keep[i]) continue;
            const formats::SceneNode& source = scene.nodes[i];
            tinygltf::Node& node = model.nodes[static_cast<size_t>(gltfNodeOf[s][i])];
            node.name = source.name;
            setTransform(node, affineOf(source.localTransform), true, source.path);
            for (int child : source.children)
                if (keep[static_cast<size_t>(child)])
                    node.children.push_back(gltfNodeOf[s][static_cast<size_t>(child)]);
            if (source.parent < 0) model.nodes[0].children.push_back(gltfNodeOf[s][i]);
            std::vector<int> meshes;
            for (int m : source.meshes)
                if (exportsMesh(i, m)) meshes.push_back(m);
            if (meshes.empty()) continue;
            auto found = gltfMeshOf.find(meshes);
            if (found == gltfMeshOf.end()) {
                tinygltf::Mesh mesh;
                mesh.name = scene.meshes[static_cast<size_t>(meshes.front())].name;
                for (int m : meshes) {
                    const SceneMeshAccessors& a = meshAccessors[static_cast<size_t>(m)];
                    tinygltf::Primitive primitive;
                    primitive.mode = TINYGLTF_MODE_TRIANGLES;
                    primitive.attributes["POSITION"] = a.position;
                    if (a.normal >= 0) primitive.attributes["NORMAL"] = a.normal;
                    primitive.indices = a.indices;
                    mesh.primitives.push_back(primitive);
                }
                model.meshes.push_back(mesh);
                found = gltfMeshOf.emplace(meshes, static_cast<int>(model.meshes.size()) - 1).first;
            }
            node.mesh = found->second;
        }
        report.sceneNodeCount += static_cast<int>(std::count(keep.begin(), keep.end(), 1));
        reportProgress(
            options, 0.4 * static_cast<double>(s + 1) / static_cast<double>(scenes.size()), output);
    }

    // Hoses: a skinned mesh each.
    rig::HoseRigDescriptor descriptor;
    descriptor.generator = options.generator;
    for (size_t h = 0; h < hoses.size(); ++h) {
        const ExportHose& input = hoses[h];
        const Hose& hose = input.hose;
        const std::string label = input.name.empty() ? input.id : input.name;
        const auto warnings = hoseWarnings(hose, "hose '" + input.id + "'");
        report.warnings.insert(report.warnings.end(), warnings.begin(), warnings.end());

        rig::RigHose rigHose;
        rigHose.id = input.id;
        rigHose.name = input.name;
        rigHose.axis = hose.points();
        for (int s = 0; s < hose.segmentCount(); ++s)
            rigHose.restLengths.push_back(hose.restLength(s));
        rigHose.expansionCoefficient = hose.material().expansionCoefficient;
        rigHose.bendLimit = hose.material().bendLimit;
        for (int j = 1; j + 1 < hose.pointCount(); ++j) {
            const double limit = hose.deflectionLimit(j);
            rigHose.jointBendLimits.push_back(limit);
            if (hose.material().bendLimit.kind == BendLimit::Kind::MinBendRadius &&
                limit < 3.141592653589793)
                rigHose.jointMinBendRadii.push_back(hose.material().bendLimit.value);
            else
                rigHose.jointMinBendRadii.push_back(
                    bendRadiusOfTurn(0.5 * (hose.restLength(j - 1) + hose.restLength(j)), limit));
        }
        rigHose.outerDiameter = hose.spec().outerDiameter;
        rigHose.crossSection = rig::CrossSection::of(hose.profile());
        rigHose.baseColour = input.baseColour;
        rigHose.roughness = input.roughness;
        rigHose.gravity = hose.spec().gravity;
        rigHose.torsion = hose.spec().torsion;

        // The distinct bodies the hose is fixed to (a scene node, or the world).
        std::set<std::pair<int, int>> fixedTo;
        for (const NodeRef& ref : input.attachedNodes)
            fixedTo.insert(ref.scene >= 0 ? std::make_pair(ref.scene, ref.node)
                                          : std::make_pair(-1, -1));
        // Static: every point fixed, all to one body. Such a hose never deforms at run time:
        // at most its one node moves it rigidly, which a plain mesh under that node does in
        // every viewer.
        const bool isStatic = options.plainMeshesForStaticHoses && fixedTo.size() == 1 &&
                              hose.attachments().size() > 0 && [&] {
                                  for (int i = 0; i < hose.pointCount(); ++i)
                                      if (!hose.isFixed(i)) return false;
                                  return true;
                              }();
        // Fixed to one scene node only: all joints hang under the hose's rig node below that
        // node, so the skin's joints have a common root of their own (Blender: one armature
        // per hose) and moving the node still carries the fixed segment.
        const bool singleNode =
            options.jointsUnderAttachedNodes && fixedTo.size() == 1 && fixedTo.begin()->first >= 0;

        // Which glTF node each axis point's joint hangs under (−1: the hose's rig node).
        std::vector<int> parentOfPoint(static_cast<size_t>(hose.pointCount()), -1);
        std::vector<const formats::Mat4*> parentWorld(static_cast<size_t>(hose.pointCount()),
                                                      nullptr);
        std::vector<formats::Mat4> attachedWorld(hose.attachments().size());
        for (size_t k = 0; k < hose.attachments().size(); ++k) {
            const Hose::Attachment& attachment = hose.attachments()[k];
            const NodeRef& ref = input.attachedNodes[k];
            rig::RigAttachment rigAttachment;
            rigAttachment.frame = attachment.frame;
            rigAttachment.firstPoint = attachment.first;
            rigAttachment.lastPoint = attachment.last;
            if (ref.scene >= 0) {
                const formats::ImportedScene& scene = *scenes[static_cast<size_t>(ref.scene)];
                rigAttachment.node =
                    gltfNodeOf[static_cast<size_t>(ref.scene)][static_cast<size_t>(ref.node)];
                rigAttachment.offset = scene.worldFrame(ref.node).inverse() * attachment.frame;
                attachedWorld[k] = scene.worldTransform(ref.node);
                if (options.jointsUnderAttachedNodes && !singleNode)
                    for (int i = attachment.first; i <= attachment.last; ++i) {
                        parentOfPoint[static_cast<size_t>(i)] = rigAttachment.node;
                        parentWorld[static_cast<size_t>(i)] = &attachedWorld[k];
                    }
            } else {
                rigAttachment.offset = attachment.frame;
            }
            rigHose.attachments.push_back(rigAttachment);
        }
        for (int i = 0; i < hose.pointCount(); ++i)
            if (!hose.isFixed(i)) rigHose.grabbablePoints.push_back(i);

        // Bind pose: the surface as the library computes it now.
        const HoseSurface surface(hose);
        const SurfaceTopology& topology = surface.topology();
        const std::vector<RingFrame>& frames = surface.frames();
        const Vec3 origin = hose.origin();

        // The free joints hang under a "<name> joints" node placed under the deepest common
        // ancestor of the attachment nodes (moving the machine moves the whole hose in a plain
        // viewer), or under the root for a free hose or attachments in different scenes.
        int rigParent = 0;
        formats::Mat4 rigWorld = formats::Mat4::Identity();
        if (!isStatic) {
            int commonScene = -2, common = -1;
            for (const NodeRef& ref : input.attachedNodes) {
                if (!options.jointsUnderAttachedNodes || ref.scene < 0 ||
                    (commonScene != -2 && ref.scene != commonScene)) {
                    commonScene = -1;
                    break;
                }
                const formats::ImportedScene& scene = *scenes[static_cast<size_t>(ref.scene)];
                if (commonScene == -2) {
                    commonScene = ref.scene;
                    common = ref.node;
                    continue;
                }
                std::vector<int> ancestors;
                for (int n = ref.node; n >= 0; n = scene.nodes[static_cast<size_t>(n)].parent)
                    ancestors.push_back(n);
                while (common >= 0 &&
                       std::find(ancestors.begin(), ancestors.end(), common) == ancestors.end())
                    common = scene.nodes[static_cast<size_t>(common)].parent;
            }
            if (commonScene >= 0 && common >= 0) {
                const formats::ImportedScene& scene = *scenes[static_cast<size_t>(commonScene)];
                rig::NodeTransform ignored;
                if (rig::detail::decompose(affineOf(scene.worldTransform(common)), ignored)) {
                    rigParent =
                        gltfNodeOf[static_cast<size_t>(commonScene)][static_cast<size_t>(common)];
                    rigWorld = scene.worldTransform(common);
                }
            }
        }
        if (!isStatic) {
            tinygltf::Node rigNode;
            rigNode.name = input.id + " joints";
            rigHose.rigNode = static_cast<int>(model.nodes.size());
            model.nodes.push_back(rigNode);
            model.nodes[static_cast<size_t>(rigParent)].children.push_back(rigHose.rigNode);

            tinygltf::Skin skin;
            skin.name = label;
            std::vector<float> inverseBind;
            inverseBind.reserve(16 * frames.size());
            for (size_t i = 0; i < frames.size(); ++i) {
                Frame world;
                world.translation = origin + frames[i].center;
                world.rotation = frames[i].rotation();
                const Affine worldMatrix = rig::detail::matrixOf(world);
                const Affine inverse = rig::detail::matrixOf(world.inverse());
                for (int k = 0; k < 16; ++k)
                    inverseBind.push_back(static_cast<float>(inverse.data()[k]));
                // glTF wants the last row exactly 0 0 0 1.
                for (int k = 3; k < 16; k += 4)
                    inverseBind[inverseBind.size() - 16 + static_cast<size_t>(k)] =
                        k == 15 ? 1.0f : 0.0f;

                tinygltf::Node joint;
                joint.name =
                    input.id + " joint " + std::to_string(i); // ids are unique, names may repeat
                const int parent = parentOfPoint[i];
                const Affine local = Affine(
                    affineOf(parent >= 0 ? *parentWorld[i] : rigWorld).inverse() * worldMatrix);
                setTransform(joint, local, false,
                             "hose '" + input.id + "' joint " + std::to_string(i));
                const int jointIndex = static_cast<int>(model.nodes.size());
                model.nodes.push_back(joint);
                model.nodes[static_cast<size_t>(parent >= 0 ? parent : rigHose.rigNode)]
                    .children.push_back(jointIndex);
                skin.joints.push_back(jointIndex);
                rigHose.jointNodes.push_back(jointIndex);
            }
            skin.inverseBindMatrices = buffer.accessor(
                buffer.view(inverseBind.data(), inverseBind.size() * sizeof(float), 0),
                TINYGLTF_COMPONENT_TYPE_FLOAT, frames.size(), TINYGLTF_TYPE_MAT4);
            model.bufferViews[static_cast<size_t>(model.accessors.back().bufferView)].target = 0;
            model.skins.push_back(skin);
            rigHose.skin = static_cast<int>(model.skins.size()) - 1;
            report.jointCount += static_cast<int>(frames.size());
        }

        // Vertices in world metres (the skinned node sits at the root with no transform).
        const std::span<const float> local = surface.positions();
        std::vector<float> positions(local.size());
        for (size_t v = 0; v < local.size(); ++v)
            positions[v] = static_cast<float>(static_cast<double>(local[v]) +
                                              origin(static_cast<Eigen::Index>(v % 3)));
        tinygltf::Primitive primitive;
        primitive.mode = TINYGLTF_MODE_TRIANGLES;
        primitive.attributes["POSITION"] = buffer.vec3Floats(positions, true);
        primitive.attributes["NORMAL"] =
            buffer.vec3Floats(unitNormals({surface.normals().begin(), surface.normals().end()}), false);
        if (options.writeTextureCoordinates) {
            const int v =
                buffer.view(topology.uvs.data(), topology.uvs.size() * sizeof(float), kArrayBuffer);
            primitive.attributes["TEXCOORD_0"] = buffer.accessor(
                v, TINYGLTF_COMPONENT_TYPE_FLOAT, topology.uvs.size() / 2, TINYGLTF_TYPE_VEC2);
        }
        const size_t vertexCount = topology.vertexRing.size();
        if (isStatic) {
            // No skin: the vertices stay as they are (world metres, see the node below).
        } else if (frames.size() <= 256) {
            std::vector<std::uint8_t> joints(4 * vertexCount, 0);
            for (size_t v = 0; v < vertexCount; ++v)
                joints[4 * v] = static_cast<std::uint8_t>(topology.vertexRing[v]);
            primitive.attributes["JOINTS_0"] = buffer.accessor(
                buffer.view(joints.data(), joints.size(), kArrayBuffer),
                TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, vertexCount, TINYGLTF_TYPE_VEC4);
        } else {
            std::vector<std::uint16_t> joints(4 * vertexCount, 0);
            for (size_t v = 0; v < vertexCount; ++v)
                joints[4 * v] = static_cast<std::uint16_t>(topology.vertexRing[v]);
            primitive.attributes["JOINTS_0"] = buffer.accessor(
                buffer.view(joints.data(), joints.size() * 2, kArrayBuffer),
                TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, vertexCount, TINYGLTF_TYPE_VEC4);
        }
        if (!isStatic) {
            std::vector<float> weights(4 * vertexCount, 0.0f);
            for (size_t v = 0; v < vertexCount; ++v)
                weights[4 * v] = 1.0f;
            primitive.attributes["WEIGHTS_0"] = buffer.accessor(
                buffer.view(weights.data(), weights.size() * sizeof(float), kArrayBuffer),
                TINYGLTF_COMPONENT_TYPE_FLOAT, vertexCount, TINYGLTF_TYPE_VEC4);
        }
        primitive.indices = buffer.indices(topology.indices, vertexCount);

        tinygltf::Material material;
        material.name = label;
        material.pbrMetallicRoughness.baseColorFactor = {input.baseColour[0], input.baseColour[1],
                                                         input.baseColour[2], input.baseColour[3]};
        material.pbrMetallicRoughness.metallicFactor = 0.0;
        material.pbrMetallicRoughness.roughnessFactor = input.roughness;
        if (input.baseColour[3] < 1.0) material.alphaMode = "BLEND";
        model.materials.push_back(material);
        primitive.material = static_cast<int>(model.materials.size()) - 1;

        tinygltf::Mesh mesh;
        mesh.name = label;
        mesh.primitives.push_back(primitive);
        model.meshes.push_back(mesh);

        tinygltf::Node meshNode;
        meshNode.name = label;
        meshNode.mesh = static_cast<int>(model.meshes.size()) - 1;
        rigHose.meshNode = static_cast<int>(model.nodes.size());
        if (isStatic) {
            // A plain mesh under the node it is fixed to (the project root for the world), with
            // the inverse of that node's world transform: its world transform is the identity
            // at export, so the world-metre vertices appear where the skinned hose would, and
            // moving the node carries the mesh.
            rigHose.isStatic = true;
            const NodeRef& ref = input.attachedNodes.front();
            int parent = 0;
            if (ref.scene >= 0) {
                const formats::ImportedScene& scene = *scenes[static_cast<size_t>(ref.scene)];
                parent = gltfNodeOf[static_cast<size_t>(ref.scene)][static_cast<size_t>(ref.node)];
                setTransform(meshNode, Affine(affineOf(scene.worldTransform(ref.node)).inverse()),
                             true, "hose '" + input.id + "'");
            }
            model.nodes.push_back(meshNode);
            model.nodes[static_cast<size_t>(parent)].children.push_back(rigHose.meshNode);
        } else {
            meshNode.skin = rigHose.skin;
            model.nodes.push_back(meshNode);
            gltfScene.nodes.push_back(rigHose.meshNode); // skinned meshes live at the scene root
        }

        descriptor.hoses.push_back(std::move(rigHose));
        reportProgress(options,
                       0.4 + 0.4 * static_cast<double>(h + 1) / static_cast<double>(hoses.size()),
                       output);
    }
    for (const NodeRef& ref : options.colliders)
        descriptor.colliders.push_back(
            gltfNodeOf[static_cast<size_t>(ref.scene)][static_cast<size_t>(ref.node)]);
    std::sort(descriptor.colliders.begin(), descriptor.colliders.end());
    descriptor.colliders.erase(
        std::unique(descriptor.colliders.begin(), descriptor.colliders.end()),
        descriptor.colliders.end());
    model.scenes.push_back(gltfScene);
    model.defaultScene = 0;
    model.buffers[0].data = buffer.bytes();
    if (model.buffers[0].data.empty()) model.buffers.clear();

    // tinygltf serialises the model; the descriptor is then set as plain JSON, so that empty
    // lists stay [] (tinygltf::Value writes an empty array as null) and numbers keep full
    // double precision.
    std::ostringstream stream;
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, stream, false, container == Container::Glb))
        throw formats::FileError(output, "tinygltf could not serialise the model");
    std::string written = stream.str();
    std::string jsonText = written;
    if (container == Container::Glb) {
        std::uint32_t jsonLength = 0;
        std::memcpy(&jsonLength, written.data() + 12, 4);
        jsonText = written.substr(20, jsonLength);
    }
    nlohmann::ordered_json gltf = nlohmann::ordered_json::parse(jsonText);
    const std::string descriptorText = rig::serialiseDescriptor(descriptor);
    gltf["extensions"][rig::kExtensionName] = nlohmann::ordered_json::parse(descriptorText);
    fs::path binFile;
    if (container == Container::Gltf && !model.buffers.empty()) {
        binFile = output;
        binFile.replace_extension(".bin");
        gltf["buffers"][0]["uri"] = binFile.filename().string();
    }
    reportProgress(options, 0.9, output);

    fs::path descriptorFile = output;
    descriptorFile.replace_extension(".hoses.json");
    std::vector<std::pair<fs::path, std::string>> files;
    if (!binFile.empty())
        files.emplace_back(binFile,
                           std::string(model.buffers[0].data.begin(), model.buffers[0].data.end()));
    if (options.writeSidecarDescriptor) files.emplace_back(descriptorFile, descriptorText);
    files.emplace_back(output, container == Container::Glb
                                   ? glbBytes(gltf.dump(), model.buffers.empty()
                                                               ? std::vector<unsigned char>{}
                                                               : model.buffers[0].data)
                                   : gltf.dump(1) + "\n");
    // Every file is first written completely beside its target (<file>.partial); only when all
    // are on disk are they renamed over the targets, so a full disk or a write error leaves a
    // previous export's .glb/.gltf, .bin and .hoses.json all as they were (not a new sidecar
    // beside an old glTF). The glTF itself is renamed last: it is what readers open.
    struct Staged
    {
        fs::path partial;
        fs::path target;
        bool targetExisted = false;
    };
    std::vector<Staged> staged;
    try {
        for (const auto& [file, contents] : files) {
            std::error_code error;
            if (fs::is_directory(file, error))
                throw formats::FileError(file, "cannot replace the file: it is a folder");
            fs::path partial = file;
            partial += ".partial";
            const bool existed = fs::exists(file, error);
            formats::writeFileAtomically(partial, contents);
            staged.push_back({partial, file, existed});
            report.bytesWritten += contents.size();
        }
    } catch (...) {
        std::error_code ignored;
        for (const Staged& s : staged)
            fs::remove(s.partial, ignored);
        throw;
    }
    // Renames within one folder fail only in exotic cases (the folder's permissions changed
    // meanwhile): then the files this call created are removed again and the staged ones
    // deleted; a target already replaced cannot be given back.
    for (size_t i = 0; i < staged.size(); ++i) {
        std::error_code error;
        fs::rename(staged[i].partial, staged[i].target, error);
        if (!error) continue;
        std::error_code ignored;
        for (size_t j = 0; j < staged.size(); ++j) {
            if (j < i && !staged[j].targetExisted) fs::remove(staged[j].target, ignored);
            if (j >= i) fs::remove(staged[j].partial, ignored);
        }
        throw formats::FileError(staged[i].target, "cannot replace the file: " + error.message());
    }
    report.gltfFile = output;
    report.binFile = binFile;
    if (options.writeSidecarDescriptor) report.descriptorFile = descriptorFile;
    report.hoseCount = static_cast<int>(hoses.size());
    report.descriptor = std::move(descriptor);
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    reportProgress(options, 1.0, output);
    return report;
}

ExportReport exportProject(const formats::Project& project, const fs::path& projectFile,
                           fs::path output, const formats::NamedRoots& roots,
                           const ExportOptions& options)
{
    const auto started = std::chrono::steady_clock::now();
    if (output.empty()) {
        const fs::path folder = projectFile.parent_path();
        const std::string extension = project.exportSettings.format == "gltf" ? ".gltf" : ".glb";
        if (!project.exportSettings.path.empty())
            output = formats::resolveProjectPath(project.exportSettings.path, folder, roots);
        else
            output = folder / (projectFile.stem().string() + extension);
    }
    const auto importProgress = [&](double fraction) {
        return !options.progress || options.progress(0.55 * fraction);
    };
    // Scene paths and hose definitions come from the project: their errors name it.
    formats::ImportedScenes imported;
    std::vector<const formats::ImportedScene*> scenes;
    std::vector<ExportHose> hoses;
    std::vector<NodeRef> colliders = options.colliders;
    try {
        imported = formats::importProjectScenes(project, projectFile, roots, importProgress);
        std::map<std::string, int> sceneIndex;
        for (const formats::SceneReference& reference : project.scenes) {
            sceneIndex[reference.id] = static_cast<int>(scenes.size());
            scenes.push_back(&imported.at(reference.id));
        }
        for (size_t h = 0; h < project.hoses.size(); ++h) {
            const formats::HoseDefinition& definition = project.hoses[h];
            Hose built = formats::buildHose(project, definition, imported);
            // A gravity hose is written as it hangs, as the editor shows it.
            formats::settleUnderGravity(built, definition, project, imported);
            ExportHose hose{definition.id,
                            definition.name,
                            std::move(built),
                            {},
                            {definition.colour.r, definition.colour.g, definition.colour.b,
                             definition.colour.a},
                            definition.roughness};
            for (const formats::HoseAttachment& attachment : definition.attachments) {
                const int s = sceneIndex.at(attachment.scene);
                hose.attachedNodes.push_back(
                    {s, scenes[static_cast<size_t>(s)]->findNode(attachment.node)});
            }
            hoses.push_back(std::move(hose));
            // Building the hoses (a gravity hose settles, up to kSettleStepBudget steps): 55–60 %.
            const double done = static_cast<double>(h + 1) / static_cast<double>(project.hoses.size());
            reportProgress(options, std::min(0.6, 0.55 + 0.05 * done), output);
        }
        for (size_t c = 0; c < project.colliders.size(); ++c) {
            const formats::ColliderNode& collider = project.colliders[c];
            const auto s = sceneIndex.find(collider.scene);
            const int node = s == sceneIndex.end()
                                 ? -1
                                 : scenes[static_cast<size_t>(s->second)]->findNode(collider.node);
            if (node < 0)
                throw InvalidArgument("/colliders/" + std::to_string(c) + "/node: scene '" +
                                      collider.scene + "' has no node '" + collider.node + "'");
            colliders.push_back({s->second, node});
        }
        // Moved parts (project.poses): the hoses were built at the file pose and followed the
        // parts (buildHose); the scene is written with the posed node transforms.
        imported = formats::posedScenes(project, std::move(imported));
        for (size_t s = 0; s < project.scenes.size(); ++s)
            scenes[s] = &imported.at(project.scenes[s].id);
    } catch (const formats::PathError& error) {
        throw formats::FileError(projectFile, error.what());
    } catch (const InvalidArgument& error) {
        const std::string what = error.what();
        if (what.find(projectFile.string()) != std::string::npos) throw;
        throw InvalidArgument(projectFile.string() + ": " + what);
    }
    ExportOptions exportOptions = options;
    exportOptions.colliders = colliders;
    exportOptions.includeSceneMeshes =
        options.includeSceneMeshes && project.exportSettings.includeScene;
    if (options.progress)
        exportOptions.progress = [&](double fraction) {
            return options.progress(0.6 + 0.4 * fraction);
        };
    ExportReport report = exportRig(scenes, hoses, project.name, output, exportOptions);
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return report;
}

ExportReport exportProjectFile(const fs::path& projectFile, const fs::path& output,
                               const formats::NamedRoots& roots, const ExportOptions& options)
{
    formats::ProjectLoadOptions load;
    load.roots = roots;
    const formats::Project project = formats::loadProject(projectFile, load);
    return exportProject(project, projectFile, output, roots, options);
}

} // namespace chaintube::exporting
