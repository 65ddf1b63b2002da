// One hose of an export: its descriptor entry, its joints placed under the nodes they follow,
// its skin and its mesh (exporters/README.md, "What is in the glTF").
#include "chaintube/surface.h"
#include "gltf_model.h"

#include <algorithm>
#include <set>
#include <span>
#include <utility>

namespace chaintube::exporting::detail {

rig::RigHose writeHose(tinygltf::Model& model, BufferWriter& buffer, tinygltf::Scene& gltfScene,
                       const std::vector<const formats::ImportedScene*>& scenes,
                       const GltfNodeOf& gltfNodeOf, const ExportHose& input,
                       const ExportOptions& options, ExportReport& report)
{
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
    if (const auto plugs = options.plugs.find(input.id); plugs != options.plugs.end()) {
        rigHose.plugStart = plugs->second.start;
        rigHose.plugEnd = plugs->second.end;
    }
    rigHose.gravity = hose.spec().gravity;
    rigHose.torsion = hose.spec().torsion;

    // The distinct bodies the hose is fixed to (a scene node, or the world). A clip does not
    // fix the hose (it slides through it): its node is not one of them.
    std::set<std::pair<int, int>> fixedTo;
    bool hasClips = false;
    for (size_t k = 0; k < input.attachedNodes.size(); ++k) {
        const NodeRef& ref = input.attachedNodes[k];
        if (hose.attachments()[k].isClip()) {
            hasClips = true;
            continue;
        }
        fixedTo.insert(ref.scene >= 0 ? std::make_pair(ref.scene, ref.node)
                                      : std::make_pair(-1, -1));
    }
    // Static: every point fixed, all to one body, no clip. Such a hose never deforms at run
    // time: at most its one node moves it rigidly, which a plain mesh under that node does in
    // every viewer.
    const bool isStatic =
        options.plainMeshesForStaticHoses && fixedTo.size() == 1 && !hasClips && [&] {
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
    std::vector<const formats::Mat4*> parentWorld(static_cast<size_t>(hose.pointCount()), nullptr);
    std::vector<formats::Mat4> attachedWorld(hose.attachments().size());
    for (size_t k = 0; k < hose.attachments().size(); ++k) {
        const Hose::Attachment& attachment = hose.attachments()[k];
        const NodeRef& ref = input.attachedNodes[k];
        if (attachment.isClip()) {
            // A clip's points slide at run time: their joints stay with the free ones.
            rig::RigClip clip;
            clip.frame = attachment.frame;
            clip.offset = attachment.frame;
            if (ref.scene >= 0) {
                const formats::ImportedScene& scene = *scenes[static_cast<size_t>(ref.scene)];
                clip.node =
                    gltfNodeOf[static_cast<size_t>(ref.scene)][static_cast<size_t>(ref.node)];
                clip.offset = scene.worldFrame(ref.node).inverse() * attachment.frame;
            }
            clip.place = attachment.slide;
            clip.hold = attachment.hold;
            clip.slideMin = attachment.slideMin;
            clip.slideMax = attachment.slideMax;
            rigHose.clips.push_back(clip);
            continue;
        }
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
    // Grabbable: every point no attachment fixes. The points a clip holds are among them, as the
    // clip slides they change, and the runtime refuses a grab only while a clip holds the point.
    std::vector<unsigned char> attached(static_cast<size_t>(hose.pointCount()), 0);
    for (const Hose::Attachment& attachment : hose.attachments())
        if (!attachment.isClip())
            std::fill(attached.begin() + attachment.first, attached.begin() + attachment.last + 1,
                      1);
    for (int i = 0; i < hose.pointCount(); ++i)
        if (!attached[static_cast<size_t>(i)]) rigHose.grabbablePoints.push_back(i);

    // Bind pose: the surface as the library computes it now.
    const HoseSurface surface(hose);
    const SurfaceTopology& topology = surface.topology();
    const std::vector<RingFrame>& frames = surface.frames();
    const Vec3 origin = hose.origin();

    // The free joints hang under a "<name> joints" node placed under the deepest common
    // ancestor of the attachment nodes (moving the machine moves the whole hose in a plain
    // viewer), or under the root for a free hose or attachments in different scenes. Clips'
    // nodes do not count: their points are free joints.
    int rigParent = 0;
    formats::Mat4 rigWorld = formats::Mat4::Identity();
    if (!isStatic) {
        int commonScene = -2, common = -1;
        for (size_t k = 0; k < input.attachedNodes.size(); ++k) {
            const NodeRef& ref = input.attachedNodes[k];
            if (hose.attachments()[k].isClip()) continue;
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
            const Affine local =
                Affine(affineOf(parent >= 0 ? *parentWorld[i] : rigWorld).inverse() * worldMatrix);
            setTransform(joint, local, false, "hose '" + input.id + "' joint " + std::to_string(i));
            const int jointIndex = static_cast<int>(model.nodes.size());
            model.nodes.push_back(joint);
            model.nodes[static_cast<size_t>(parent >= 0 ? parent : rigHose.rigNode)]
                .children.push_back(jointIndex);
            skin.joints.push_back(jointIndex);
            rigHose.jointNodes.push_back(jointIndex);
        }
        skin.inverseBindMatrices =
            buffer.accessor(buffer.view(inverseBind.data(), inverseBind.size() * sizeof(float), 0),
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
        primitive.attributes["JOINTS_0"] =
            buffer.accessor(buffer.view(joints.data(), joints.size(), kArrayBuffer),
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
            setTransform(meshNode, Affine(affineOf(scene.worldTransform(ref.node)).inverse()), true,
                         "hose '" + input.id + "'");
        }
        model.nodes.push_back(meshNode);
        model.nodes[static_cast<size_t>(parent)].children.push_back(rigHose.meshNode);
    } else {
        meshNode.skin = rigHose.skin;
        model.nodes.push_back(meshNode);
        gltfScene.nodes.push_back(rigHose.meshNode); // skinned meshes live at the scene root
    }

    return rigHose;
}

} // namespace chaintube::exporting::detail
