// exportRig: the glTF of an export — the scenes' nodes and meshes under one root, each hose
// (hose_skin.cpp), the descriptor — then the files (rig_files.cpp). hoseWarnings.
#include "chaintube/export/gltf_export.h"

#include "chaintube/formats/errors.h"
#include "chaintube/metrics.h"
#include "gltf_model.h"

#include <algorithm>
#include <chrono>
#include <map>

namespace chaintube::exporting {

namespace fs = std::filesystem;
using namespace detail;

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

    for (size_t m = 0; m < options.motions.size(); ++m) {
        const NodeRef& ref = options.motions[m].node;
        if (ref.scene < 0 || ref.scene >= static_cast<int>(scenes.size()) ||
            !scenes[static_cast<size_t>(ref.scene)] || ref.node < 0 ||
            ref.node >= static_cast<int>(scenes[static_cast<size_t>(ref.scene)]->nodes.size()))
            throw InvalidArgument("motions[" + std::to_string(m) + "] '" +
                                  options.motions[m].motion.id + "': scene " +
                                  std::to_string(ref.scene) + " node " + std::to_string(ref.node) +
                                  " does not exist");
    }

    for (size_t k = 0; k < options.sockets.size(); ++k) {
        const NodeRef& ref = options.sockets[k].node;
        if (ref.scene == -1) continue; // in world coordinates
        if (ref.scene < 0 || ref.scene >= static_cast<int>(scenes.size()) ||
            !scenes[static_cast<size_t>(ref.scene)] || ref.node < 0 ||
            ref.node >= static_cast<int>(scenes[static_cast<size_t>(ref.scene)]->nodes.size()))
            throw InvalidArgument("sockets[" + std::to_string(k) + "] '" +
                                  options.sockets[k].socket.id + "': scene " +
                                  std::to_string(ref.scene) + " node " + std::to_string(ref.node) +
                                  " does not exist");
        if (!(options.sockets[k].socket.axis.norm() > 1e-9))
            throw InvalidArgument("sockets[" + std::to_string(k) + "] '" +
                                  options.sockets[k].socket.id + "': zero axis");
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
        for (const ExportOptions::Motion& motion : options.motions)
            if (motion.node.scene == static_cast<int>(s))
                keep[static_cast<size_t>(motion.node.node)] = 1;
        for (const ExportOptions::Socket& socket : options.sockets)
            if (socket.node.scene == static_cast<int>(s))
                keep[static_cast<size_t>(socket.node.node)] = 1;
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

    // Hoses: a skinned mesh each (or a plain mesh for a static hose).
    rig::HoseRigDescriptor descriptor;
    descriptor.generator = options.generator;
    for (size_t h = 0; h < hoses.size(); ++h) {
        descriptor.hoses.push_back(
            writeHose(model, buffer, gltfScene, scenes, gltfNodeOf, hoses[h], options, report));
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
    for (const ExportOptions::Motion& motion : options.motions) {
        descriptor.motions.push_back(motion.motion);
        descriptor.motions.back().node = gltfNodeOf[static_cast<size_t>(motion.node.scene)]
                                                   [static_cast<size_t>(motion.node.node)];
    }
    for (const ExportOptions::Socket& source : options.sockets) {
        rig::RigSocket socket = source.socket;
        socket.axis = socket.axis.normalized();
        Frame world = Frame::identity();
        socket.node = -1;
        socket.nodeName.clear();
        if (source.node.scene >= 0) {
            const formats::ImportedScene& scene = *scenes[static_cast<size_t>(source.node.scene)];
            world = scene.worldFrame(source.node.node);
            socket.node = gltfNodeOf[static_cast<size_t>(source.node.scene)]
                                    [static_cast<size_t>(source.node.node)];
            socket.nodeName = model.nodes[static_cast<size_t>(socket.node)].name;
        }
        socket.worldPosition = world.apply(socket.position);
        socket.worldAxis = (world.rotation * socket.axis).normalized();
        descriptor.sockets.push_back(socket);
    }
    model.scenes.push_back(gltfScene);
    model.defaultScene = 0;
    model.buffers[0].data = buffer.bytes();
    if (model.buffers[0].data.empty()) model.buffers.clear();

    writeRigFiles(model, descriptor, container, output, options, report);
    report.hoseCount = static_cast<int>(hoses.size());
    report.descriptor = std::move(descriptor);
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    reportProgress(options, 1.0, output);
    return report;
}

} // namespace chaintube::exporting
