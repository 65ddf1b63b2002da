// ChainTube formats — turning a project's hose definitions into chaintube::Hose objects.
#pragma once

#include "chaintube/formats/project.h"
#include "chaintube/formats/scene_import.h"
#include "chaintube/collision.h"
#include "chaintube/hose.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace chaintube::formats {

/// Imported scenes by SceneReference::id.
using ImportedScenes = std::map<std::string, ImportedScene>;

/// Imports every scene of the project (paths resolved with resolveScenePath(), import
/// settings applied). Throws PathError, FileError, Cancelled as importScene() does.
ImportedScenes importProjectScenes(const Project& project, const std::filesystem::path& projectFile,
                                   const NamedRoots& roots,
                                   const std::function<bool(double)>& progress = {});

/// The HoseSpec of a hose definition (material preset resolved, profile built).
/// Throws InvalidArgument (unknown preset, out-of-range profile).
HoseSpec hoseSpecOf(const Project& project, const HoseDefinition& hose);

/// Builds hose `hose` of the project: Hose::alongRoute(route, spec), then every attachment
/// fixed with Hose::attach(first, last, frame) where frame = scene node's rigid world frame ·
/// offset (ImportedScene::worldFrame). The points keep their route positions (world metres).
/// `scenes` must be at their file pose (as importProjectScenes gives them). If project.poses
/// moves an attached node (or one of its ancestors), the attachments are then moved together
/// to the posed frames (Hose::moveAttachments, one update): the hose follows the part, as in
/// the editor. Throws InvalidArgument for an unknown scene id or node path (of an attachment
/// or a pose), or a point range outside the built hose.
Hose buildHose(const Project& project, const HoseDefinition& hose, const ImportedScenes& scenes);

/// world ← node transform of `node` of scene `sceneId` with project.poses applied along the
/// parent chain (`scenes` at their file pose). Throws InvalidArgument for an unknown scene, a
/// node index out of range, or a pose naming a node the scene does not have.
Mat4 posedWorldTransform(const Project& project, const ImportedScenes& scenes,
                         const std::string& sceneId, int node);

/// The scenes with project.poses written into their nodes' local transforms (what the export
/// writes as the scene's node transforms). Throws InvalidArgument naming the pose for an
/// unknown scene id or node path.
ImportedScenes posedScenes(const Project& project, ImportedScenes scenes);

/// The triangles of node `node`'s own meshes (not its children's) as a rigid MeshCollider at
/// the node's world transform `world` (e.g. posedWorldTransform): the transform's scale and
/// shear are baked into the vertices, its rigid part (rigidPart) is the collider's frame, so a
/// pose that only moves the node can be applied with setFrame(). nullptr when the node has no
/// triangle. Used by the clearance check and the editor's live colliders.
std::shared_ptr<MeshCollider> nodeCollider(const ImportedScene& scene, int node, const Mat4& world);

/// True if one of `hose`'s attachments exempts node `nodePath` of scene `sceneId` from it
/// (collider_exemption.h's rule on paths): the hose neither collides with that node nor is
/// checked for clearance against it.
bool attachmentsExempt(const HoseDefinition& hose, const std::string& sceneId, const std::string& nodePath);

/// How many gravity steps settleUnderGravity() takes at most (the editor's budget per hose).
constexpr int kSettleStepBudget = 3000;

/// A hose with HoseSpec::gravity on, brought to rest as the editor shows it: Hose::step() until
/// no point moves (at most stepBudget steps), against the project's colliders except those its
/// attachments exempt (collider_exemption.h; colliders at the posed world transforms). The
/// hose's own colliders are left empty again and it is marked settled (Hose::markSettled).
/// Returns the steps taken (0 with gravity off). The export writes gravity hoses in this shape,
/// so viewers and the runtime start from the sag the editor shows.
int settleUnderGravity(Hose& hose, const HoseDefinition& definition, const Project& project,
                       const ImportedScenes& scenes, int stepBudget = kSettleStepBudget);

/// buildHose() for every hose, in project order.
std::vector<Hose> buildHoses(const Project& project, const ImportedScenes& scenes);

} // namespace chaintube::formats
