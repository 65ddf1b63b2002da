// Moving parts: hinge and slider transforms, the nodes they carry.
#include "chaintube/formats/motion.h"

#include <cmath>

namespace chaintube::formats {

namespace {

Mat4 matrixOf(const Frame& frame)
{
    Mat4 matrix = Mat4::Identity();
    matrix.topLeftCorner<3, 3>() = frame.rotation.toRotationMatrix();
    matrix.topRightCorner<3, 1>() = frame.translation;
    return matrix;
}

} // namespace

Frame motionFrame(const PartMotion& motion, double value)
{
    const Vec3 axis = motion.axis.normalized();
    if (motion.kind == PartMotion::Kind::Slider) return {Quat::Identity(), value * axis};
    const Quat rotation(Eigen::AngleAxisd(value, axis));
    // About the axis through `point`: p → point + R (p − point).
    return {rotation, motion.point - rotation * motion.point};
}

double motionValueAt(const PartMotion& motion, double t)
{
    return motion.minimum + t * (motion.maximum - motion.minimum);
}

PartMotions::PartMotions(const Project& project, const ImportedScenes& scenes)
    : m_posed(posedScenes(project, scenes))
{
    for (const auto& [sceneId, scene] : m_posed)
        m_carried[sceneId].assign(scene.nodes.size(), 0);
    for (size_t i = 0; i < project.motions.size(); ++i) {
        const PartMotion& motion = project.motions[i];
        const std::string name =
            "motion '" + motion.id + "' (/motions/" + std::to_string(i) + "): ";
        const auto scene = m_posed.find(motion.scene);
        if (scene == m_posed.end())
            throw InvalidArgument(name + "scene '" + motion.scene + "' is not imported");
        const int node = scene->second.findNode(motion.node);
        if (node < 0)
            throw InvalidArgument(name + "scene '" + motion.scene + "' has no node '" +
                                  motion.node + "'");
        Moving moving;
        moving.motion = motion;
        moving.sceneId = motion.scene;
        moving.node = node;
        moving.restLocal = scene->second.nodes[static_cast<size_t>(node)].localTransform;
        moving.restWorld = scene->second.worldTransform(node);
        moving.restWorldInverse = moving.restWorld.inverse();
        m_moving.push_back(std::move(moving));
        // A parent always comes before its children (scene.h): one pass marks every node
        // under a moving one.
        std::vector<char>& carried = m_carried[motion.scene];
        carried[static_cast<size_t>(node)] = 1;
    }
    for (auto& [sceneId, carried] : m_carried) {
        const std::vector<SceneNode>& nodes = m_posed.at(sceneId).nodes;
        for (size_t n = 0; n < nodes.size(); ++n)
            if (nodes[n].parent >= 0 && carried[static_cast<size_t>(nodes[n].parent)])
                carried[n] = 1;
    }
}

void PartMotions::apply(const std::vector<double>& values, ImportedScenes& scenes) const
{
    if (values.size() != m_moving.size())
        throw InvalidArgument("motion values: expected " + std::to_string(m_moving.size()) +
                              " (one per motion), got " + std::to_string(values.size()));
    for (size_t i = 0; i < m_moving.size(); ++i) {
        const Moving& moving = m_moving[i];
        if (!std::isfinite(values[i]))
            throw InvalidArgument("motion '" + moving.motion.id +
                                  "': expected a finite value, got " + std::to_string(values[i]));
        // world = parent world · local; at rest parent world = restWorld · restLocal⁻¹, so
        // local = restLocal · restWorld⁻¹ · M · restWorld gives world = M · restWorld while the
        // parent rests, and carries M along when the parent moves.
        scenes.at(moving.sceneId).nodes[static_cast<size_t>(moving.node)].localTransform =
            moving.restLocal * moving.restWorldInverse *
            matrixOf(motionFrame(moving.motion, values[i])) * moving.restWorld;
    }
}

bool PartMotions::carried(const std::string& sceneId, int node) const
{
    const auto found = m_carried.find(sceneId);
    return found != m_carried.end() && node >= 0 && node < static_cast<int>(found->second.size()) &&
           found->second[static_cast<size_t>(node)] != 0;
}

} // namespace chaintube::formats
