// Clearance analysis of a project: hoses against scene objects.
#include "chaintube/export/clearance.h"

#include "chaintube/formats/project_hoses.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace chaintube::exporting {

std::vector<SceneObject> sceneObjects(const formats::Project& project,
                                      const formats::ImportedScenes& scenes)
{
    std::vector<SceneObject> objects;
    for (const formats::SceneReference& reference : project.scenes) {
        const auto found = scenes.find(reference.id);
        if (found == scenes.end()) continue; // not imported (the caller decided): no objects
        const formats::ImportedScene& scene = found->second;
        for (int node = 0; node < static_cast<int>(scene.nodes.size()); ++node) {
            std::shared_ptr<MeshCollider> collider = formats::nodeCollider(
                scene, node, formats::posedWorldTransform(project, scenes, reference.id, node));
            if (!collider) continue;
            objects.push_back({reference.id, node, scene.nodes[static_cast<size_t>(node)].path,
                               std::move(collider)});
        }
    }
    return objects;
}

std::vector<ClearanceFinding> clearanceViolations(const formats::Project& project,
                                                  const std::vector<Hose>& hoses,
                                                  const std::vector<SceneObject>& objects,
                                                  const ClearanceOptions& options)
{
    std::vector<const Hose*> pointers;
    for (const Hose& hose : hoses)
        pointers.push_back(&hose);
    return clearanceViolations(project, pointers, objects, options);
}

std::vector<ClearanceFinding> clearanceViolations(const formats::Project& project,
                                                  const std::vector<const Hose*>& hoses,
                                                  const std::vector<SceneObject>& objects,
                                                  const ClearanceOptions& options)
{
    if (!(options.threshold >= 0.0) || !std::isfinite(options.threshold))
        throw InvalidArgument("clearance threshold: expected a finite distance ≥ 0 metres, got " +
                              std::to_string(options.threshold));
    if (hoses.size() != project.hoses.size())
        throw InvalidArgument("clearance: " + std::to_string(hoses.size()) + " built hoses for " +
                              std::to_string(project.hoses.size()) + " hose definitions");
    std::vector<ClearanceFinding> findings;
    for (size_t h = 0; h < hoses.size(); ++h) {
        if (!hoses[h]) continue;
        const Hose& hose = *hoses[h];
        const formats::HoseDefinition& definition = project.hoses[h];
        // A hose end sits in the part it is attached to by design: skip that node and every
        // ancestor of it (an attachment on "/rig/valve/inlet" sits in "/rig/valve" too), the
        // rule the runtime and the editor use for colliders (formats/collider_exemption.h).
        const auto exempt = [&](const SceneObject& object) {
            return !options.includeAttachedNodes &&
                   formats::attachmentsExempt(definition, object.sceneId, object.path);
        };
        // Objects whose bounds are farther than threshold + radius from the hose's box are skipped.
        Aabb hoseBox;
        for (int i = 0; i < hose.pointCount(); ++i)
            hoseBox.extend(hose.point(i));
        const double reach = options.threshold + hose.outerRadius();
        hoseBox.min.array() -= reach;
        hoseBox.max.array() += reach;
        for (size_t o = 0; o < objects.size(); ++o) {
            const SceneObject& object = objects[o];
            if (exempt(object)) continue;
            const Aabb box = object.collider->worldBounds();
            if ((box.min.array() > hoseBox.max.array()).any() ||
                (box.max.array() < hoseBox.min.array()).any())
                continue;
            const Clearance c = clearance(hose, *object.collider, options.threshold);
            if (!c.found || !(c.distance < options.threshold)) continue;
            ClearanceFinding finding;
            finding.hose = static_cast<int>(h);
            finding.hoseId = definition.id;
            finding.object = static_cast<int>(o);
            finding.sceneId = object.sceneId;
            finding.objectPath = object.path;
            finding.distance = c.distance;
            finding.axisPoint = c.axisPoint;
            finding.onHose = c.onSurface;
            finding.onObject = c.onObject;
            findings.push_back(std::move(finding));
        }
    }
    std::stable_sort(findings.begin(), findings.end(),
                     [](const ClearanceFinding& a, const ClearanceFinding& b) {
                         return a.distance < b.distance;
                     });
    return findings;
}

std::vector<ClearanceFinding> checkProjectClearance(const std::filesystem::path& projectFile,
                                                    const formats::NamedRoots& roots,
                                                    const ClearanceOptions& options)
{
    formats::ProjectLoadOptions load;
    load.roots = roots;
    const formats::Project project = formats::loadProject(projectFile, load);
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, projectFile, roots);
    std::vector<Hose> hoses = formats::buildHoses(project, scenes);
    // Gravity hoses as they hang: what the editor shows and the export writes.
    for (size_t h = 0; h < hoses.size(); ++h)
        formats::settleUnderGravity(hoses[h], project.hoses[h], project, scenes);
    return clearanceViolations(project, hoses, sceneObjects(project, scenes), options);
}

} // namespace chaintube::exporting
