// From a project to an export: import its scenes, build (and settle) its hoses, then exportRig.
// What the editor's Export dialog and `chaintube export` call.
#include "chaintube/formats/errors.h"
#include "chaintube/formats/project_hoses.h"
#include "gltf_model.h"

#include <algorithm>
#include <chrono>
#include <map>

namespace chaintube::exporting {

namespace fs = std::filesystem;
using detail::reportProgress;

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
    std::vector<ExportOptions::Motion> motions = options.motions;
    std::vector<ExportOptions::Socket> sockets = options.sockets;
    std::map<std::string, ExportOptions::Plugs> plugs = options.plugs;
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
            if (!definition.plugs.empty())
                plugs[definition.id] = {definition.plugs.start, definition.plugs.end};
            for (const formats::HoseAttachment& attachment : definition.attachments) {
                const int s = sceneIndex.at(attachment.scene);
                hose.attachedNodes.push_back(
                    {s, scenes[static_cast<size_t>(s)]->findNode(attachment.node)});
            }
            for (const formats::HoseClip& clip : definition.clips) { // after the attachments
                const int s = sceneIndex.at(clip.scene);
                hose.attachedNodes.push_back(
                    {s, scenes[static_cast<size_t>(s)]->findNode(clip.node)});
            }
            hoses.push_back(std::move(hose));
            // Building the hoses (a gravity hose settles, up to kSettleStepBudget steps): 55–60 %.
            const double done =
                static_cast<double>(h + 1) / static_cast<double>(project.hoses.size());
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
        for (size_t m = 0; m < project.motions.size(); ++m) {
            const formats::PartMotion& source = project.motions[m];
            const auto s = sceneIndex.find(source.scene);
            const int node = s == sceneIndex.end()
                                 ? -1
                                 : scenes[static_cast<size_t>(s->second)]->findNode(source.node);
            if (node < 0)
                throw InvalidArgument("/motions/" + std::to_string(m) + "/node: scene '" +
                                      source.scene + "' has no node '" + source.node + "'");
            rig::RigMotion motion;
            motion.id = source.id;
            motion.kind = source.kind == formats::PartMotion::Kind::Hinge
                              ? rig::RigMotion::Kind::Hinge
                              : rig::RigMotion::Kind::Slider;
            motion.axis = source.axis.normalized();
            if (motion.kind == rig::RigMotion::Kind::Hinge) motion.point = source.point;
            motion.minimum = source.minimum;
            motion.maximum = source.maximum;
            motions.push_back({{s->second, node}, motion});
        }
        for (size_t k = 0; k < project.sockets.size(); ++k) {
            const formats::Socket& source = project.sockets[k];
            const auto s = sceneIndex.find(source.scene);
            const int node = s == sceneIndex.end()
                                 ? -1
                                 : scenes[static_cast<size_t>(s->second)]->findNode(source.node);
            if (node < 0)
                throw InvalidArgument("/sockets/" + std::to_string(k) + "/node: scene '" +
                                      source.scene + "' has no node '" + source.node + "'");
            rig::RigSocket socket;
            socket.id = source.id;
            socket.position = source.position;
            socket.axis = source.axis;
            socket.captureRadius = source.captureRadius;
            socket.captureAngle = source.captureAngle;
            socket.tag = source.tag;
            sockets.push_back({{s->second, node}, socket});
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
    exportOptions.motions = motions;
    exportOptions.sockets = sockets;
    exportOptions.plugs = plugs;
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
