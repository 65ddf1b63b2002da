// ChainTube formats — moving parts (project.motions, format 1.4): where a hinge or a slider puts
// its node for a motion value, and which nodes it carries.
#pragma once

#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"

#include <map>
#include <string>
#include <vector>

namespace chaintube::formats {

/// The rigid world transform a motion applies at `value` (radians for a hinge: right-handed
/// about the normalised axis through `point`; metres for a slider: along the normalised axis):
/// a point of the part at world p in the project's pose goes to motionFrame(m, v).apply(p).
/// Value 0 is the identity. No range check (the caller keeps values in [minimum, maximum]).
Frame motionFrame(const PartMotion& motion, double value);

/// The value of a motion at drive parameter t ∈ [0, 1]: minimum + t · (maximum − minimum).
double motionValueAt(const PartMotion& motion, double t);

/// The project's motions resolved against its imported scenes: the node each one moves, the
/// nodes it carries (the node and everything under it), and the scenes' node transforms for a
/// set of motion values. The editor's motion slider and the sweep (exporting::sweepMotions)
/// pose the parts with it.
class PartMotions
{
public:
    /// `scenes` at their file pose (importProjectScenes). Throws InvalidArgument naming the
    /// motion (its id and /motions/i) when its scene is not imported or has no such node, and
    /// for a pose naming an unknown node (as posedScenes()).
    PartMotions(const Project& project, const ImportedScenes& scenes);

    /// The scenes in the project's pose: project.poses applied, every motion at value 0.
    const ImportedScenes& posed() const { return m_posed; }

    /// Writes into `scenes` (a copy of posed()) each moving node's parent ← node transform for
    /// `values` (one per project.motions, radians or metres). A moving node's world transform
    /// becomes motionFrame(value) · its world transform in the project's pose, times the
    /// motions of its moving ancestors: a motion's axis and point travel with the parts above
    /// it. Throws InvalidArgument when `values` has the wrong size or a non-finite value.
    void apply(const std::vector<double>& values, ImportedScenes& scenes) const;

    /// True when node `node` of scene `sceneId` moves with some motion (it or an ancestor is a
    /// moving node).
    bool carried(const std::string& sceneId, int node) const;

    /// Scene id and node index of motion `motion` (index into project.motions).
    const std::string& sceneOf(size_t motion) const { return m_moving[motion].sceneId; }
    int nodeOf(size_t motion) const { return m_moving[motion].node; }
    size_t size() const { return m_moving.size(); }

private:
    struct Moving
    {
        PartMotion motion;
        std::string sceneId;
        int node = -1;
        Mat4 restLocal = Mat4::Identity(); ///< parent ← node in the project's pose
        Mat4 restWorld = Mat4::Identity(); ///< world ← node in the project's pose
        Mat4 restWorldInverse = Mat4::Identity();
    };
    ImportedScenes m_posed;
    std::vector<Moving> m_moving;
    std::map<std::string, std::vector<char>> m_carried; ///< per scene, per node
};

} // namespace chaintube::formats
