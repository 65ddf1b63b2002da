// The runtime in Python: Rig, an exported rig running its hoses.
#include "module_support.h"

namespace chaintube::python {

void bindRuntime(py::module_& m)
{
    // --- runtime ----------------------------------------------------------------------------
    py::class_<rig::HoseRuntime>(
        m, "Rig",
        "An exported rig running its hoses (the runtime a VR platform links): Rig.load reads a "
        ".glb/.gltf\nwith its descriptor and rebuilds every hose. Per frame: set_node_transform "
        "for parts that moved,\ngrab for hands, update(), then joint_poses(hose) to pose the "
        "skinned meshes.")
        .def_static(
            "load",
            [](const fs::path& file) {
                return std::make_unique<rig::HoseRuntime>(rig::HoseRuntime::load(file));
            },
            py::arg("path"), "Raises UnreadableFile, DescriptorError or Error naming the file.")
        .def_property_readonly("hose_count", &rig::HoseRuntime::hoseCount, "Hoses of the rig.")
        .def_property_readonly("node_count", &rig::HoseRuntime::nodeCount, "glTF nodes of the rig.")
        .def("find_hose", &rig::HoseRuntime::findHose, py::arg("id"),
             "Index of the hose with this descriptor id, or -1.")
        .def("find_node", &rig::HoseRuntime::findNode, py::arg("name"),
             "Index of the first node with this name, or -1.")
        .def(
            "hose_id", [](const rig::HoseRuntime& r, int h) { return r.description(h).id; },
            py::arg("hose"))
        .def(
            "node_name", [](const rig::HoseRuntime& r, int n) { return r.node(n).name; },
            py::arg("node"))
        .def(
            "set_node_transform",
            [](rig::HoseRuntime& r, int node, const py::object& translation,
               const py::object& rotation, const py::object& scale) {
                rig::NodeTransform local;
                local.translation = toVec3(translation, "translation");
                local.rotation = toQuat(rotation, "rotation");
                local.scale = toVec3(scale, "scale");
                py::list updates;
                for (const rig::HoseUpdate& update : r.setNodeTransform(node, local))
                    updates.append(py::make_tuple(update.hose, update.result));
                return updates;
            },
            py::arg("node"), py::arg("translation"),
            py::arg("rotation") = py::make_tuple(0, 0, 0, 1),
            py::arg("scale") = py::make_tuple(1, 1, 1),
            "A scene object moved: its local transform (glTF parent space, rotation x, y, z, w). "
            "The hoses\nattached to it or below it follow. Returns [(hose, UpdateResult)]; a bad "
            "node or transform\ngives [(-1, InvalidInput)].")
        .def(
            "grab",
            [](rig::HoseRuntime& r, int hose, int point, const py::object& target) {
                return r.grab(hose, point, toVec3(target, "target"));
            },
            py::arg("hose"), py::arg("point"), py::arg("target"),
            "A hand pulls free point `point` of hose `hose` to `target` (world metres).")
        .def(
            "release",
            [](rig::HoseRuntime& r, int hose) { return static_cast<bool>(r.release(hose)); },
            py::arg("hose"),
            "Lets go of the held point (a free end in a socket's capture snaps in). False for a "
            "bad hose.")
        .def(
            "update", [](rig::HoseRuntime& r, double seconds) { return r.update(seconds); },
            py::arg("seconds") = Gravity::kFrameSeconds,
            "Once per frame, with the frame's time in (0, 0.1] s (default 1/90 s): gravity "
            "steps, surfaces\nand joint poses brought up to date. Returns the number of hoses "
            "recomputed. A bad time\nraises ValueError (InvalidArgument), nothing changed.")
        .def("frame_result", &rig::HoseRuntime::frameResult, py::arg("hose"),
             "What happened to the hose in the frame the last update() closed.")
        .def(
            "hose_points",
            [](const rig::HoseRuntime& r, int hose) { return pointsArray(r.hose(hose).points()); },
            py::arg("hose"), "The hose's axis points, (n, 3) world metres (a copy).")
        .def(
            "joint_poses",
            [](const rig::HoseRuntime& r, int hose) {
                const std::vector<rig::JointPose>& poses = r.jointPoses(hose);
                const auto n = static_cast<py::ssize_t>(poses.size());
                py::array_t<int> nodes(n);
                py::array_t<double> translation({n, py::ssize_t{3}}), rotation({n, py::ssize_t{4}}),
                    scale({n, py::ssize_t{3}}), worldTranslation({n, py::ssize_t{3}}),
                    worldRotation({n, py::ssize_t{4}});
                for (py::ssize_t j = 0; j < n; ++j) {
                    const rig::JointPose& pose = poses[static_cast<size_t>(j)];
                    nodes.mutable_data()[j] = pose.node;
                    const Quat& q = pose.local.rotation;
                    const Quat& w = pose.world.rotation;
                    for (int k = 0; k < 3; ++k) {
                        translation.mutable_data()[3 * j + k] = pose.local.translation[k];
                        scale.mutable_data()[3 * j + k] = pose.local.scale[k];
                        worldTranslation.mutable_data()[3 * j + k] = pose.world.translation[k];
                    }
                    const double local[4] = {q.x(), q.y(), q.z(), q.w()};
                    const double world[4] = {w.x(), w.y(), w.z(), w.w()};
                    for (int k = 0; k < 4; ++k) {
                        rotation.mutable_data()[4 * j + k] = local[k];
                        worldRotation.mutable_data()[4 * j + k] = world[k];
                    }
                }
                py::dict d;
                d["node"] = nodes;
                d["translation"] = translation;
                d["rotation"] = rotation;
                d["scale"] = scale;
                d["world_translation"] = worldTranslation;
                d["world_rotation"] = worldRotation;
                return d;
            },
            py::arg("hose"),
            "The hose's joint poses as of the last update(), axis order, as NumPy arrays: "
            "{'node' (n,),\n'translation' (n, 3), 'rotation' (n, 4) x y z w, 'scale' (n, 3)} in "
            "the joint node's parent frame\n(what to write into the glTF node's TRS) and "
            "{'world_translation', 'world_rotation'}. Empty\nfor a static hose.")
        .def(
            "world_positions",
            [](const rig::HoseRuntime& r, int hose) {
                const std::vector<float> positions = r.worldPositions(hose);
                py::array_t<float> array(
                    {static_cast<py::ssize_t>(positions.size() / 3), py::ssize_t{3}});
                std::copy(positions.begin(), positions.end(), array.mutable_data());
                return array;
            },
            py::arg("hose"), "Surface vertex positions, (v, 3) float32 world metres.");
}

} // namespace chaintube::python
