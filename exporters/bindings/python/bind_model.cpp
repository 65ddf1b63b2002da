// The model in Python: Status, UpdateResult, Material, HoseSpec and Hose.
#include "module_support.h"

namespace chaintube::python {

void bindModel(py::module_& m)
{
    // --- model ------------------------------------------------------------------------------
    py::enum_<Status>(m, "Status",
                      "What an update did (always look at it): Ok, Clamped (a grab target not "
                      "reached this update), Infeasible (attachments leave no valid shape), "
                      "InvalidInput (rejected, the hose unchanged).")
        .value("Ok", Status::Ok)
        .value("Clamped", Status::Clamped)
        .value("Infeasible", Status::Infeasible)
        .value("InvalidInput", Status::InvalidInput);

    py::class_<UpdateResult>(m, "UpdateResult",
                             "What an update did. Every update does a bounded amount of work; "
                             "unless Infeasible every segment is in its stretch band and every "
                             "joint within its limit.")
        .def_readonly("status", &UpdateResult::status, "What the update did (Status).")
        .def_readonly("length_violation", &UpdateResult::lengthViolation,
                      "Largest length violation beyond the stretch band, relative (0: none).")
        .def_readonly("angle_violation", &UpdateResult::angleViolation,
                      "Largest bend violation beyond a joint's limit, radians (0: none).")
        .def_readonly("grab_error", &UpdateResult::grabError,
                      "Metres between the grab target and where the point ended up.")
        .def_readonly("moved_points", &UpdateResult::movedPoints,
                      "Number of axis points whose position changed.")
        .def_readonly("blocked", &UpdateResult::blocked,
                      "A collider kept the update from being met.")
        .def_readonly("penetration", &UpdateResult::penetration,
                      "Deepest remaining penetration into a collider, metres.")
        .def_readonly("contacts", &UpdateResult::contacts, "Axis points touching a collider.")
        .def_readonly("iterations", &UpdateResult::iterations,
                      "Newton steps of the solvers (the work done, bounded per update).")
        .def_property_readonly("ok", &UpdateResult::ok, "status is Status.Ok.")
        .def("__repr__", [](const UpdateResult& r) {
            return "UpdateResult(status=" + std::string(toString(r.status)) +
                   ", moved_points=" + std::to_string(r.movedPoints) + ")";
        });

    py::class_<Material>(m, "Material",
                         "Hose material: the stretch band and the bend limit.\n\n"
                         "expansion_coefficient: allowed relative change of every segment's "
                         "length, in [0, 1).\nThe bend limit is either a minimum bend radius "
                         "(metres to the centreline, 0: none;\nthe per-joint angle follows from "
                         "the segment length) or a deflection angle per joint\n(radians in "
                         "[0, pi)). Invalid values raise InvalidArgument naming the field.")
        .def(py::init([](double expansion, std::optional<double> minBendRadius,
                         std::optional<double> deflectionAngle) {
                 if (minBendRadius && deflectionAngle)
                     throw InvalidArgument("Material: give min_bend_radius or deflection_angle, "
                                           "not both");
                 Material material;
                 material.expansionCoefficient = expansion;
                 if (deflectionAngle)
                     material.bendLimit = BendLimit::deflectionAngle(*deflectionAngle);
                 else
                     material.bendLimit = BendLimit::minBendRadius(minBendRadius.value_or(0.05));
                 material.validate();
                 return material;
             }),
             py::arg("expansion_coefficient") = 0.05, py::arg("min_bend_radius") = py::none(),
             py::arg("deflection_angle") = py::none())
        .def_property(
            "expansion_coefficient", [](const Material& x) { return x.expansionCoefficient; },
            [](Material& x, double value) {
                Material changed = x;
                changed.expansionCoefficient = value;
                changed.validate();
                x = changed;
            },
            "Relative stretch band of every segment, [0, 1).")
        .def_property(
            "min_bend_radius",
            [](const Material& x) -> std::optional<double> {
                if (x.bendLimit.kind != BendLimit::Kind::MinBendRadius) return std::nullopt;
                return x.bendLimit.value;
            },
            [](Material& x, double metres) { x.bendLimit = BendLimit::minBendRadius(metres); },
            "Minimum bend radius in metres (None when the limit is a deflection angle).")
        .def_property(
            "deflection_angle",
            [](const Material& x) -> std::optional<double> {
                if (x.bendLimit.kind != BendLimit::Kind::DeflectionAngle) return std::nullopt;
                return x.bendLimit.value;
            },
            [](Material& x, double radians) { x.bendLimit = BendLimit::deflectionAngle(radians); },
            "Deflection limit per joint in radians (None when the limit is a radius).")
        .def("__eq__", [](const Material& a, const Material& b) { return a == b; })
        .def("__repr__", [](const Material& x) {
            return "Material(expansion_coefficient=" + std::to_string(x.expansionCoefficient) +
                   (x.bendLimit.kind == BendLimit::Kind::MinBendRadius ? ", min_bend_radius="
                                                                       : ", deflection_angle=") +
                   std::to_string(x.bendLimit.value) + ")";
        });

    py::class_<HoseSpec>(m, "HoseSpec",
                         "Parameters that make a hose: outer diameter (metres > 0), material, "
                         "resolution\n(segment_count 1 ... 1,000,000, or 0 to use "
                         "segment_length in metres), gravity and torsion.\nA 16-sided circular "
                         "cross-section.")
        .def(py::init([](double outerDiameter, const Material& material, int segmentCount,
                         double segmentLength, bool gravity, double twistLimit, bool torsion) {
                 HoseSpec spec;
                 spec.outerDiameter = outerDiameter;
                 spec.material = material;
                 spec.segmentCount = segmentCount;
                 spec.segmentLength = segmentLength;
                 spec.gravity.enabled = gravity;
                 spec.torsion.enabled = torsion;
                 spec.torsion.twistLimit = twistLimit;
                 spec.validate();
                 return spec;
             }),
             py::arg("outer_diameter") = 0.02, py::arg("material") = Material(),
             py::arg("segment_count") = 0, py::arg("segment_length") = 0.02,
             py::arg("gravity") = false, py::arg("twist_limit") = 0.1, py::arg("torsion") = false)
        .def_readwrite("outer_diameter", &HoseSpec::outerDiameter, "Metres > 0.")
        .def_readwrite("material", &HoseSpec::material,
                       "The Material (a copy: assign a changed one).")
        .def_readwrite("segment_count", &HoseSpec::segmentCount,
                       "Axis segments, 1 ... 1,000,000; 0: segment_length decides.")
        .def_readwrite("segment_length", &HoseSpec::segmentLength,
                       "Target segment length in metres when segment_count is 0.")
        .def_property(
            "gravity", [](const HoseSpec& s) { return s.gravity.enabled; },
            [](HoseSpec& s, bool on) { s.gravity.enabled = on; }, "Per-frame gravity (Hose.step).")
        .def_property(
            "gravity_direction", [](const HoseSpec& s) { return vec3Array(s.gravity.direction); },
            [](HoseSpec& s, const py::object& v) {
                s.gravity.direction = toVec3(v, "gravity_direction");
            },
            "World direction of gravity (need not be unit).")
        .def("validate", &HoseSpec::validate,
             "Raises InvalidArgument naming a field out of range.");

    py::class_<PyHose>(
        m, "Hose",
        "One hose: a chain of axis points p0 ... pn with per-segment rest lengths, a stretch "
        "band\nand a per-joint deflection limit, plus attachments (runs of points fixed to "
        "frames) and\nclips (guides it slides through). Positions are world metres.\n\n"
        "Updates (grab, move_attachment, step) never raise: they return an UpdateResult whose "
        "status\nsays what happened (Status.InvalidInput for NaN, an index out of range or "
        "grabbing a\nfixed point; the hose is then unchanged). Set-up calls (along_route, "
        "attach, add_clip)\nraise InvalidArgument naming the parameter.\n\n"
        "points is a read-only (n, 3) NumPy view of a world-coordinate buffer the Hose keeps "
        "up to\ndate after every call made through Python: the same memory for the hose's "
        "life, no copy\nper access (hold it and read it again after a grab).")
        .def_static(
            "along_route",
            [](const py::object& route, const HoseSpec& spec) {
                return PyHose(Hose::alongRoute(toPoints(route, "route"), spec));
            },
            py::arg("route"), py::arg("spec") = HoseSpec(),
            "A hose laid along a route ((n, 3), n >= 2, consecutive points distinct): interior "
            "corners\nrounded with the minimum bend radius, the axis sampled at equal arc "
            "length, relaxed\n(rest lengths are the sampled chords). Raises InvalidArgument.")
        .def_static(
            "straight",
            [](const py::object& start, const py::object& direction, double length,
               const HoseSpec& spec) {
                return PyHose(Hose::straight(toVec3(start, "start"), toVec3(direction, "direction"),
                                             length, spec));
            },
            py::arg("start"), py::arg("direction"), py::arg("length"), py::arg("spec") = HoseSpec(),
            "A straight hose of `length` metres (> 0) from `start` along `direction` (non-zero).")
        .def_static(
            "from_axis",
            [](const py::object& points, const HoseSpec& spec) {
                return PyHose(Hose::fromAxis(toPoints(points, "points"), spec));
            },
            py::arg("points"), py::arg("spec") = HoseSpec(),
            "A hose through exactly these axis points ((n, 3), n >= 2); their distances become "
            "the rest lengths.")
        .def_property_readonly(
            "points",
            [](py::object self) {
                PyHose& h = self.cast<PyHose&>();
                py::array_t<double> view(
                    {static_cast<py::ssize_t>(h.hose.pointCount()), py::ssize_t{3}}, h.world.data(),
                    self);
                py::detail::array_proxy(view.ptr())->flags &=
                    ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
                return view;
            },
            "World positions of the axis points, (n, 3) metres: a read-only view (no copy) that "
            "follows\nthe hose after every call made through Python.")
        .def_property_readonly(
            "point_count", [](const PyHose& h) { return h.hose.pointCount(); },
            "Number of axis points (segments + 1).")
        .def_property_readonly(
            "segment_count", [](const PyHose& h) { return h.hose.segmentCount(); },
            "Number of segments (point_count - 1).")
        .def(
            "point",
            [](const PyHose& h, int i) {
                if (i < 0 || i >= h.hose.pointCount())
                    throw py::index_error("point " + std::to_string(i) + " of a hose with " +
                                          std::to_string(h.hose.pointCount()) + " points");
                return vec3Array(h.hose.point(i));
            },
            py::arg("index"), "World position of axis point `index` (a copy).")
        .def_property_readonly(
            "rest_lengths",
            [](const PyHose& h) {
                py::array_t<double> lengths(h.hose.segmentCount());
                for (int s = 0; s < h.hose.segmentCount(); ++s)
                    lengths.mutable_data()[s] = h.hose.restLength(s);
                return lengths;
            },
            "Rest length of every segment, metres (a copy).")
        .def_property_readonly(
            "rest_length", [](const PyHose& h) { return h.hose.restLengthTotal(); },
            "Total rest length of the axis, metres.")
        .def_property_readonly(
            "current_length", [](const PyHose& h) { return h.hose.currentLength(); },
            "Current length of the axis polyline, metres.")
        .def_property_readonly(
            "outer_radius", [](const PyHose& h) { return h.hose.outerRadius(); }, "Metres.")
        .def_property_readonly(
            "material", [](const PyHose& h) { return h.hose.material(); }, "A copy.")
        .def_property_readonly(
            "held_point", [](const PyHose& h) { return h.hose.heldPoint(); },
            "The point held by the last grab (-1: none).")
        .def_property_readonly(
            "revision", [](const PyHose& h) { return h.hose.revision(); },
            "Incremented whenever an axis point, the profile or the diameter changes.")
        .def(
            "grab",
            [](PyHose& h, int index, const py::object& target) {
                const UpdateResult result = h.hose.grab(index, toVec3(target, "target"));
                h.refresh();
                return result;
            },
            py::arg("index"), py::arg("target"),
            "Move free axis point `index` towards `target` (world metres); the rest of the "
            "hose\nfollows and the point is held until the next grab or release_grab(). Fixed "
            "points never\nmove; a target beyond reach is replaced by the nearest reachable "
            "point (Status.Clamped).\nBounded work per call. Returns an UpdateResult.")
        .def(
            "release_grab",
            [](PyHose& h) {
                h.hose.releaseGrab();
                h.refresh();
            },
            "Let go of the held point.")
        .def(
            "step",
            [](PyHose& h, double seconds) {
                const UpdateResult result = h.hose.step(seconds);
                h.refresh();
                return result;
            },
            py::arg("seconds") = Gravity::kFrameSeconds,
            "Per-frame gravity (HoseSpec.gravity) for a frame of `seconds` in (0, 0.1] (default "
            "1/90 s),\nin implicit steps of at most 1/90 s. A hose at rest costs one comparison. "
            "Every constraint\nholds after the call. A bad time: Status.InvalidInput, nothing "
            "changes.")
        .def(
            "settle",
            [](PyHose& h) {
                const UpdateResult result = h.hose.settle();
                h.refresh();
                return result;
            },
            "Re-impose all constraints on the current shape.")
        .def(
            "attach",
            [](PyHose& h, int first, int last, const py::object& translation,
               const py::object& rotation) {
                const int id = h.hose.attach(first, last, frameOf(translation, rotation));
                h.refresh();
                return id;
            },
            py::arg("first"), py::arg("last"), py::arg("translation") = py::make_tuple(0, 0, 0),
            py::arg("rotation") = py::make_tuple(0, 0, 0, 1),
            "Fix points first ... last (inclusive) rigidly to the frame (translation, rotation "
            "x, y, z, w)\nat their current positions. Returns the attachment id. Raises "
            "InvalidArgument.")
        .def(
            "move_attachment",
            [](PyHose& h, int id, const py::object& translation, const py::object& rotation) {
                const UpdateResult result =
                    h.hose.moveAttachment(id, frameOf(translation, rotation));
                h.refresh();
                return result;
            },
            py::arg("id"), py::arg("translation"), py::arg("rotation") = py::make_tuple(0, 0, 0, 1),
            "Move an attachment's frame; its points move rigidly and the hose follows.")
        .def(
            "detach",
            [](PyHose& h, int id) {
                const bool removed = h.hose.detach(id);
                h.refresh();
                return removed;
            },
            py::arg("id"), "Remove an attachment or clip. False for an unknown id.")
        .def(
            "add_clip",
            [](PyHose& h, double place, const py::object& translation, const py::object& rotation,
               const std::string& hold) {
                ClipOptions options;
                options.hold = holdFromName(hold);
                const int id = h.hose.addClip(place, frameOf(translation, rotation), options);
                h.refresh();
                return id;
            },
            py::arg("place"), py::arg("translation") = py::make_tuple(0, 0, 0),
            py::arg("rotation") = py::make_tuple(0, 0, 0, 1), py::arg("hold") = "sliding",
            "A clip where the hose is at rest arc length `place` (metres from point 0); the "
            "hose\nslides through it. hold: 'sliding' or 'sliding-turning'. Returns the id.")
        .def(
            "is_fixed", [](const PyHose& h, int i) { return h.hose.isFixed(i); }, py::arg("index"))
        .def(
            "attachment_gap", [](const PyHose& h, int id) { return h.hose.attachmentGap(id); },
            py::arg("id"),
            "Metres between where an attachment's frame puts its points and where they are "
            "(-1: unknown id).")
        .def(
            "measure_violation", [](const PyHose& h) { return h.hose.measureViolation(); },
            "Largest violation of the length band (relative) and of the bend limits (radians).")
        .def("__repr__", [](const PyHose& h) {
            return "Hose(points=" + std::to_string(h.hose.pointCount()) +
                   ", rest_length=" + std::to_string(h.hose.restLengthTotal()) + ")";
        });
}

} // namespace chaintube::python
