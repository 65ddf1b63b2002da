#include "chaintube/formats/project_hoses.h"

#include "chaintube/formats/collider_exemption.h"

#include <algorithm>

namespace chaintube::formats {

namespace {

Profile profileOf(const HoseDefinition& hose)
{
    const ProfileSpec& p = hose.profile;
    switch (p.shape) {
    case Profile::Shape::Circle:
        return Profile::circle(0.5 * hose.outerDiameter, p.sides);
    case Profile::Shape::Ellipse:
        return Profile::ellipse(p.semiAxisX, p.semiAxisY, p.sides);
    case Profile::Shape::Rectangle:
        return Profile::rectangle(p.width, p.height);
    case Profile::Shape::RoundedRectangle:
        return Profile::roundedRectangle(p.width, p.height, p.cornerRadius, p.cornerSegments);
    case Profile::Shape::Polygon:
        return Profile::polygon(p.points, p.smoothAngle);
    }
    throw InvalidArgument("hose '" + hose.id + "': unknown profile shape");
}

/// Node index of every pose of the project in scene `sceneId` (−1 entries never occur: an
/// unknown node path throws).
std::vector<std::pair<int, const NodePose*>> posesOfScene(const Project& project,
                                                          const ImportedScenes& scenes,
                                                          const std::string& sceneId)
{
    std::vector<std::pair<int, const NodePose*>> found;
    for (size_t i = 0; i < project.poses.size(); ++i) {
        const NodePose& pose = project.poses[i];
        if (pose.scene != sceneId) continue;
        const auto scene = scenes.find(pose.scene);
        const int node = scene == scenes.end() ? -1 : scene->second.findNode(pose.node);
        if (node < 0)
            throw InvalidArgument("pose " + std::to_string(i) + " (/poses/" + std::to_string(i) +
                                  "): scene '" + pose.scene + "' has no node '" + pose.node +
                                  "'");
        found.emplace_back(node, &pose);
    }
    return found;
}

} // namespace

std::shared_ptr<MeshCollider> nodeCollider(const ImportedScene& scene, int node, const Mat4& world)
{
    const SceneNode& sceneNode = scene.nodes.at(static_cast<size_t>(node));
    const Frame frame = rigidPart(world);
    std::vector<Vec3> positions;
    std::vector<std::uint32_t> indices;
    for (int meshIndex : sceneNode.meshes) {
        const SceneMesh& mesh = scene.meshes[static_cast<size_t>(meshIndex)];
        const auto base = static_cast<std::uint32_t>(positions.size());
        for (size_t v = 0; v < mesh.vertexCount(); ++v) {
            const Vec3 local(mesh.positions[3 * v], mesh.positions[3 * v + 1],
                             mesh.positions[3 * v + 2]);
            positions.push_back(frame.applyInverse((world * local.homogeneous()).head<3>()));
        }
        for (std::uint32_t index : mesh.indices) indices.push_back(base + index);
    }
    if (indices.empty()) return nullptr;
    return MeshCollider::fromArrays(positions, indices, frame);
}

Mat4 posedWorldTransform(const Project& project, const ImportedScenes& scenes,
                         const std::string& sceneId, int node)
{
    const auto scene = scenes.find(sceneId);
    if (scene == scenes.end())
        throw InvalidArgument("scene '" + sceneId + "' is not imported");
    const std::vector<SceneNode>& nodes = scene->second.nodes;
    if (node < 0 || node >= static_cast<int>(nodes.size()))
        throw InvalidArgument("scene '" + sceneId + "' has no node " + std::to_string(node));
    const auto poses = posesOfScene(project, scenes, sceneId);
    Mat4 world = Mat4::Identity();
    for (int n = node; n >= 0; n = nodes[static_cast<size_t>(n)].parent) {
        Mat4 local = nodes[static_cast<size_t>(n)].localTransform;
        for (const auto& [posedNode, pose] : poses)
            if (posedNode == n) local = pose->localTransform;
        world = local * world;
    }
    return world;
}

ImportedScenes posedScenes(const Project& project, ImportedScenes scenes)
{
    for (const SceneReference& reference : project.scenes) {
        const auto poses = posesOfScene(project, scenes, reference.id);
        for (const auto& [node, pose] : poses)
            scenes.at(reference.id).nodes[static_cast<size_t>(node)].localTransform =
                pose->localTransform;
    }
    for (size_t i = 0; i < project.poses.size(); ++i)
        if (!project.findScene(project.poses[i].scene))
            throw InvalidArgument("pose " + std::to_string(i) + ": unknown scene '" +
                                  project.poses[i].scene + "'");
    return scenes;
}

ImportedScenes importProjectScenes(const Project& project, const std::filesystem::path& projectFile,
                                   const NamedRoots& roots,
                                   const std::function<bool(double)>& progress)
{
    ImportedScenes scenes;
    const double count = static_cast<double>(project.scenes.size());
    for (size_t i = 0; i < project.scenes.size(); ++i) {
        const SceneReference& reference = project.scenes[i];
        ImportOptions options;
        options.metresPerUnit = reference.import.metresPerUnit;
        options.upAxis = reference.import.upAxis;
        options.chordalTolerance = reference.import.chordalTolerance;
        options.angularTolerance = reference.import.angularTolerance;
        if (progress)
            options.progress = [&](double fraction) {
                return progress((static_cast<double>(i) + fraction) / count);
            };
        scenes.emplace(reference.id,
                       importScene(resolveScenePath(reference, projectFile, roots), options));
    }
    return scenes;
}

HoseSpec hoseSpecOf(const Project& project, const HoseDefinition& hose)
{
    HoseSpec spec;
    spec.outerDiameter = hose.outerDiameter;
    spec.material = project.materialOf(hose);
    spec.segmentCount = hose.segmentCount;
    spec.segmentLength = hose.segmentLength;
    spec.profile = profileOf(hose);
    spec.gravity = hose.gravity;
    spec.torsion = hose.torsion;
    return spec;
}

Hose buildHose(const Project& project, const HoseDefinition& definition,
               const ImportedScenes& scenes)
{
    Hose hose = Hose::alongRoute(definition.route, hoseSpecOf(project, definition));
    for (const HoseAttachment& attachment : definition.attachments) {
        const auto scene = scenes.find(attachment.scene);
        if (scene == scenes.end())
            throw InvalidArgument("hose '" + definition.id + "': scene '" + attachment.scene +
                                  "' is not imported");
        const int node = scene->second.findNode(attachment.node);
        if (node < 0)
            throw InvalidArgument("hose '" + definition.id + "': scene '" + attachment.scene +
                                  "' has no node '" + attachment.node + "'");
        if (attachment.lastPoint >= hose.pointCount())
            throw InvalidArgument("hose '" + definition.id + "': attachment points [" +
                                  std::to_string(attachment.firstPoint) + ", " +
                                  std::to_string(attachment.lastPoint) + "] outside the hose's " +
                                  std::to_string(hose.pointCount()) + " axis points");
        Frame offset = attachment.offset;
        offset.rotation.normalize();
        hose.attach(attachment.firstPoint, attachment.lastPoint,
                    scene->second.worldFrame(node) * offset);
    }
    // Pose overrides: the attachments go to the posed frames in one update (the editor's
    // Document does the same when it rebuilds a hose).
    bool posed = false;
    for (const HoseAttachment& attachment : definition.attachments) {
        const ImportedScene& scene = scenes.at(attachment.scene);
        for (const auto& [posedNode, pose] : posesOfScene(project, scenes, attachment.scene))
            for (int n = scene.findNode(attachment.node); n >= 0 && !posed;
                 n = scene.nodes[static_cast<size_t>(n)].parent)
                posed = n == posedNode;
    }
    if (posed) {
        std::vector<int> ids;
        std::vector<Frame> frames;
        for (size_t a = 0; a < definition.attachments.size(); ++a) {
            const HoseAttachment& attachment = definition.attachments[a];
            Frame offset = attachment.offset;
            offset.rotation.normalize();
            const int node = scenes.at(attachment.scene).findNode(attachment.node);
            ids.push_back(hose.attachments()[a].id);
            frames.push_back(
                rigidPart(posedWorldTransform(project, scenes, attachment.scene, node)) * offset);
        }
        (void)hose.moveAttachments(ids, frames); // what it leaves is reported by measure() in the export checks
    }
    return hose;
}

bool attachmentsExempt(const HoseDefinition& hose, const std::string& sceneId, const std::string& nodePath)
{
    return std::any_of(hose.attachments.begin(), hose.attachments.end(), [&](const HoseAttachment& a) {
        return a.scene == sceneId && attachmentExemptsPath(a.node, nodePath);
    });
}

int settleUnderGravity(Hose& hose, const HoseDefinition& definition, const Project& project,
                       const ImportedScenes& scenes, int stepBudget)
{
    if (!hose.spec().gravity.enabled) return 0;
    std::vector<std::shared_ptr<const MeshCollider>> used;
    for (const ColliderNode& collider : project.colliders) {
        const auto scene = scenes.find(collider.scene);
        if (scene == scenes.end() || attachmentsExempt(definition, collider.scene, collider.node)) continue;
        const int node = scene->second.findNode(collider.node);
        if (node < 0) continue;
        if (std::shared_ptr<MeshCollider> mesh =
                nodeCollider(scene->second, node, posedWorldTransform(project, scenes, collider.scene, node)))
            used.push_back(std::move(mesh));
    }
    hose.setColliders(std::move(used));
    int steps = 0;
    while (steps < stepBudget && hose.step().movedPoints > 0) ++steps;
    hose.setColliders({});
    hose.markSettled();
    return steps;
}

std::vector<Hose> buildHoses(const Project& project, const ImportedScenes& scenes)
{
    std::vector<Hose> hoses;
    hoses.reserve(project.hoses.size());
    for (const HoseDefinition& definition : project.hoses)
        hoses.push_back(buildHose(project, definition, scenes));
    return hoses;
}

} // namespace chaintube::formats
