// ChainTube formats — turning a project's hose definitions into chaintube::Hose objects.
#pragma once

#include "chaintube/collision.h"
#include "chaintube/formats/project.h"
#include "chaintube/formats/scene_import.h"
#include "chaintube/hose.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace chaintube::formats {

/// Imported scenes by SceneReference::id.
using ImportedScenes = std::map<std::string, ImportedScene>;

/// Imports every scene of the project (paths resolved with resolveScenePath(), import
/// settings applied, placed with placeScene()). Throws PathError, FileError, Cancelled as
/// importScene() does.
ImportedScenes importProjectScenes(const Project& project, const std::filesystem::path& projectFile,
                                   const NamedRoots& roots,
                                   const std::function<bool(double)>& progress = {});

/// Moves an imported scene to where its author placed it (SceneImportSettings::placement,
/// world metres): added to the root node's translation (the root has no parent).
void placeScene(ImportedScene& scene, const Vec3& placement);

/// The HoseSpec of a hose definition (material preset resolved, profile built).
/// Throws InvalidArgument (unknown preset, out-of-range profile).
HoseSpec hoseSpecOf(const Project& project, const HoseDefinition& hose);

/// The rest length (metres) of the hose laid along its route at rest, as buildHose() lays it:
/// the route's own length when it is an axis of the hose (one point per axis point, a valid
/// shape at its mean chord), else segments × the chord of the equal-chord layout along the
/// rounded route. What files before format 1.3 are read with, so that their hoses lie on their
/// routes at rest. Throws InvalidArgument as hoseSpecOf().
double routeRestLength(const Project& project, const HoseDefinition& hose);

/// The hose's length: hose.length, or routeRestLength() when it has none.
double hoseLength(const Project& project, const HoseDefinition& hose);

/// Builds hose `hose` of the project at its file pose, then follows the poses.
///  1. The shape, every rest length length / segments: a route with one point per axis point
///     is taken as the axis as it is when it holds the hose's constraints there (to 1e-6: a
///     committed drag stores the shape so); any other route is rounded as Hose::alongRoute
///     rounds it (the minimum bend radius) and sampled with equal chords from its first to its
///     last point, so a hose as long as its route lies on it at rest. (A definition without a
///     length is Hose::alongRoute's hose.)
///  2. Every attachment fixed with Hose::attach(first, last, frame), frame = the scene node's
///     rigid world frame · offset (ImportedScene::worldFrame): the points keep their places.
///  3. A shape that then breaks the hose's constraints (a route longer or shorter than the
///     hose can stretch) is settled with both route ends held (the hose never reaches past its
///     last route point); when it cannot reach, a free last point is let go.
/// `scenes` must be at their file pose (as importProjectScenes gives them). If project.poses
/// moves an attached node (or one of its ancestors), the attachments are then moved together
/// to the posed frames (moveAttachmentsFully): the shape is a function of the poses, whatever
/// way the parts took there, and the editor shows the same. `lastUpdate`, when given, receives the
/// result of the build's last update (the settling of step 3 or the posed move; a default Ok result
/// when it made none): e.g. Status::Infeasible when a posed part is beyond the hose's reach
/// (Hose::attachmentGap says how far). Throws InvalidArgument for an unknown scene id or node path
/// (of an attachment or a pose), or a point range outside the built hose. Steps
/// moveAttachmentsFully() takes when one update leaves an attachment short.
constexpr int kPoseSubSteps = 16;

/// Hose::moveAttachments to `frames` (ids and frames of equal size); when that leaves an
/// attachment short of its frame (a long move in one update does bounded work), the move again
/// in kPoseSubSteps steps from the attachments' frames before (translations interpolated,
/// rotations slerped), then the frames again until the hose gets no nearer (at most
/// kPoseSubSteps more). Beyond the hose's reach the result stays Infeasible with the gap
/// Hose::attachmentGap() reports. Returns the last update's result. Not for a frame loop: its
/// work is up to 2 · kPoseSubSteps + 1 updates.
UpdateResult moveAttachmentsFully(Hose& hose, const std::vector<int>& ids,
                                  const std::vector<Frame>& frames);

Hose buildHose(const Project& project, const HoseDefinition& hose, const ImportedScenes& scenes,
               UpdateResult* lastUpdate = nullptr);

/// `hose` made `length` metres long (> 0, finite) where it lies: its shape at the file pose with
/// every rest length length / segments, settled inextensibly (so that added length
/// shows as slack, not as compressed segments) between the ends its attachments and its route
/// hold; a hose too short to reach its last route point lets that point go unless an
/// attachment holds it (then it stays taut and short: see Hose::attachmentGap). The route of
/// the result is that axis (buildHose takes it as it is), its length `length`. With
/// segmentLength resolution the number of segments follows the length: attachments that end
/// at the last point move with it. Clips stay where they are (centre and axis in the world, as
/// buildHose puts them): each clip's place and end stops scale with the length (the clip stays
/// at the same fraction of the hose, as attachments keep their points), except that where a
/// piece of hose between two consecutive held points (a fixed point, a clip's centre) comes
/// within 0.5 % of its straight line (from the end of the segment a clip holds along its axis)
/// the hose slides through its clips: every piece gets its straight line and 1 % (less when
/// there is not that much: the same fraction for every piece), the rest taken from the pieces
/// with more in proportion, within the end stops. The hose is laid through every clip's centre
/// along its axis and settled with the clips held; a shape that is then not valid is tried
/// again with each piece laid straight between its held points, and again with margins of 5 %
/// and 15 % (as the library's clips retry, lib/README.md "Clips"). Throws InvalidArgument as
/// buildHose, or for a length that leaves no room for the attachments.
HoseDefinition withLength(const Project& project, const HoseDefinition& hose,
                          const ImportedScenes& scenes, double length);

/// `hose` with `segments` segments (segmentCount; the Resolution field), its fixed points
/// carried over by arc length: the hose keeps its length, so axis point i of n segments lies
/// where point i · segments / n (rounded) of the new hose lies. An attachment range keeps at
/// least one segment when it had one (a fixed end keeps its direction), and a range that
/// ended at the last point ends at the new last point. Clips are placed by arc length
/// (HoseClip::place) and stay as they are. The same count gives the definition with only
/// segmentCount set. Throws InvalidArgument naming the hose for a count outside
/// 1 … 1,000,000, or when two attachments would share axis points at that resolution (the
/// message names both and the fewest segments that keeps them apart).
HoseDefinition withSegmentCount(const Project& project, const HoseDefinition& hose, int segments);

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

/// True if one of `hose`'s attachments or clips exempts node `nodePath` of scene `sceneId` from it
/// (collider_exemption.h's rule on paths): the hose neither collides with that node nor is
/// checked for clearance against it.
bool attachmentsExempt(const HoseDefinition& hose, const std::string& sceneId,
                       const std::string& nodePath);

/// How many gravity steps settleUnderGravity() takes at most; the editor's live gravity has
/// the same budget per hose (editor::Document::kGravityStepBudget).
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
