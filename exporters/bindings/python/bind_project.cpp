// Projects in Python: Project and its items, and the functions the CLI runs on them (export,
// check, sweep, fit_length, report, find_projects).
#include "module_support.h"

namespace chaintube::python {
namespace {

// --- report data as Python objects ---------------------------------------------------------------

py::dict sweepStepDict(const exporting::SweepReport& report, int step)
{
    py::dict result;
    result["index"] = step;
    if (step < 0 || step >= static_cast<int>(report.steps.size())) return result;
    const exporting::SweepStep& at = report.steps[static_cast<size_t>(step)];
    result["phase"] = exporting::toString(at.phase);
    result["t"] = at.t ? py::object(py::float_(*at.t)) : py::object(py::none());
    py::dict values;
    for (size_t m = 0; m < report.motions.size(); ++m)
        values[py::str(report.motions[m].id)] = at.values[m];
    result["values"] = values;
    return result;
}

py::dict sweepDict(const exporting::SweepReport& report)
{
    py::list hoses;
    for (const exporting::HoseSweep& hose : report.hoses) {
        py::list objects;
        for (const exporting::ObjectSweep& object : hose.objects) {
            py::dict o;
            o["scene"] = object.sceneId;
            o["object"] = object.objectPath;
            o["distance"] = optionalFloat(object.minDistance);
            o["step"] = sweepStepDict(report, object.step);
            o["axis_point"] = object.axisPoint;
            o["on_hose"] = vec3Array(object.onHose);
            o["on_object"] = vec3Array(object.onObject);
            o["steps_below_threshold"] = object.stepsBelowThreshold;
            o["collides"] = object.collides();
            objects.append(o);
        }
        py::list updates;
        for (const exporting::SweepUpdate& update : hose.updates) {
            py::dict u;
            u["step"] = sweepStepDict(report, update.step);
            u["status"] = toString(update.status);
            u["length_violation"] = update.lengthViolation;
            u["angle_violation"] = update.angleViolation;
            u["attachment_gap"] = update.attachmentGap;
            updates.append(u);
        }
        py::dict h;
        h["hose"] = hose.hoseId;
        h["driven"] = hose.driven;
        h["violates"] = hose.violates();
        h["stretch_band"] = hose.stretchBand;
        h["worst_stretch"] = hose.worstStretch;
        h["worst_stretch_step"] = sweepStepDict(report, hose.worstStretchStep);
        h["overstretched_steps"] = hose.overstretchedSteps;
        h["min_bend_radius"] = hose.minBendRadius > 0.0 ? py::object(py::float_(hose.minBendRadius))
                                                        : py::object(py::none());
        h["smallest_bend_radius"] = optionalFloat(hose.smallestBendRadius);
        h["smallest_bend_radius_step"] = sweepStepDict(report, hose.smallestBendRadiusStep);
        h["smallest_bend_radius_joint"] = hose.smallestBendRadiusJoint;
        h["bend_violation_steps"] = hose.bendViolationSteps;
        h["worst_attachment_gap"] = hose.worstAttachmentGap;
        h["unmet_steps"] = hose.unmetSteps;
        h["objects"] = objects;
        h["updates"] = updates;
        h["stretch_series"] = py::array_t<double>(
            static_cast<py::ssize_t>(hose.stretchSeries.size()), hose.stretchSeries.data());
        h["bend_radius_series"] = py::array_t<double>(
            static_cast<py::ssize_t>(hose.bendRadiusSeries.size()), hose.bendRadiusSeries.data());
        h["clearance_series"] = py::array_t<double>(
            static_cast<py::ssize_t>(hose.clearanceSeries.size()), hose.clearanceSeries.data());
        hoses.append(h);
    }
    py::list motions;
    for (const formats::PartMotion& motion : report.motions)
        motions.append(motion.id);
    py::dict result;
    result["motions"] = motions;
    result["steps"] = static_cast<int>(report.steps.size());
    result["steps_each_way"] = report.stepsEachWay;
    result["lead_in_steps"] = report.leadInSteps;
    result["clearance_threshold"] = report.clearanceThreshold;
    result["violations"] = report.violations();
    result["hoses"] = hoses;
    return result;
}

py::dict fitDict(const exporting::LengthFit& fit)
{
    py::dict d;
    d["hose"] = fit.hoseId;
    d["current_length"] = fit.currentLength;
    d["valid"] = fit.valid;
    d["shortest"] = fit.valid ? py::object(py::float_(fit.shortest)) : py::object(py::none());
    d["longest"] = fit.valid ? py::object(py::float_(fit.longest)) : py::object(py::none());
    d["longest_at_search_limit"] = fit.longestAtSearchLimit;
    d["shortest_limit"] = exporting::toString(fit.shortestLimit);
    d["longest_limit"] = exporting::toString(fit.longestLimit);
    d["invalid_by"] = exporting::toString(fit.invalidBy);
    d["limiting_object"] = fit.limitingObject;
    d["taut_bound"] = fit.tautBound;
    d["current_valid"] = fit.currentValid;
    d["converged"] = fit.converged;
    d["sweeps"] = fit.sweeps;
    d["reason"] = fit.reason;
    return d;
}

py::dict reportDict(const exporting::LengthReport& report)
{
    const auto optional = [](const std::optional<double>& value) {
        return value ? py::object(py::float_(*value)) : py::object(py::none());
    };
    py::list hoses;
    for (const exporting::HoseReport& hose : report.hoses) {
        py::dict h;
        h["project"] = hose.project;
        h["id"] = hose.hoseId;
        h["name"] = hose.hoseName;
        h["material"] = hose.material;
        h["rest_length"] = hose.restLength;
        h["fittings_allowance"] = hose.fittingsAllowance;
        h["cut_length"] = hose.cutLength;
        h["shortest_valid_length"] = optional(hose.shortestValidLength);
        h["slack"] = optional(hose.slack);
        h["fit_note"] = hose.fitNote;
        h["smallest_bend_radius"] = optional(hose.smallestBendRadius);
        h["min_bend_radius"] = hose.minBendRadius > 0.0 ? py::object(py::float_(hose.minBendRadius))
                                                        : py::object(py::none());
        h["bend_margin"] = optional(hose.bendMargin);
        h["smallest_clearance"] = optional(hose.smallestClearance);
        h["clearance_object"] = hose.clearanceObject;
        h["clearance_axis_point"] = hose.clearanceAxisPoint;
        h["clearance_point"] = hose.smallestClearance ? py::object(vec3Array(hose.clearancePoint))
                                                      : py::object(py::none());
        h["clearance_motion"] = hose.clearanceMotion;
        h["attachments"] = hose.attachments;
        h["clips"] = hose.clips;
        hoses.append(h);
    }
    py::list materials;
    for (const exporting::MaterialTotal& total : report.materials) {
        py::dict t;
        t["material"] = total.material;
        t["hoses"] = total.hoses;
        t["rest_length"] = total.restLength;
        t["fittings_allowance"] = total.fittingsAllowance;
        t["cut_length"] = total.cutLength;
        materials.append(t);
    }
    py::dict result;
    result["projects"] = report.projects;
    result["hoses"] = hoses;
    result["materials"] = materials;
    return result;
}

} // namespace

void bindProject(py::module_& m)
{
    // --- project ----------------------------------------------------------------------------
    py::class_<formats::HoseAttachment>(
        m, "Attachment",
        "A run of axis points first_point ... last_point fixed to a scene node: attach frame = "
        "the\nnode's rigid world frame * offset (translation, rotation x, y, z, w).")
        .def(py::init([](const std::string& scene, const std::string& node, int first, int last,
                         const py::object& translation, const py::object& rotation) {
                 formats::HoseAttachment a;
                 a.scene = scene;
                 a.node = node;
                 a.firstPoint = first;
                 a.lastPoint = last;
                 a.offset = frameOf(translation, rotation);
                 return a;
             }),
             py::arg("scene"), py::arg("node"), py::arg("first_point"), py::arg("last_point"),
             py::arg("translation") = py::make_tuple(0, 0, 0),
             py::arg("rotation") = py::make_tuple(0, 0, 0, 1))
        .def_readwrite("scene", &formats::HoseAttachment::scene, "Scene id.")
        .def_readwrite("node", &formats::HoseAttachment::node, "Node path, e.g. '/rig/valve'.")
        .def_readwrite("first_point", &formats::HoseAttachment::firstPoint,
                       "First axis point fixed (inclusive).")
        .def_readwrite("last_point", &formats::HoseAttachment::lastPoint,
                       "Last axis point fixed (inclusive), >= first_point.")
        .def_property(
            "translation",
            [](const formats::HoseAttachment& a) { return vec3Array(a.offset.translation); },
            [](formats::HoseAttachment& a, const py::object& v) {
                a.offset.translation = toVec3(v, "translation");
            },
            "Offset translation in the node frame, metres.")
        .def_property(
            "rotation",
            [](const formats::HoseAttachment& a) { return quatArray(a.offset.rotation); },
            [](formats::HoseAttachment& a, const py::object& v) {
                a.offset.rotation = toQuat(v, "rotation");
            },
            "x, y, z, w.")
        .def("__eq__", [](const formats::HoseAttachment& a, const formats::HoseAttachment& b) {
            return a == b;
        });

    py::class_<formats::HoseClip>(
        m, "Clip",
        "A clip on a scene node the hose passes and slides through: where the hose is at "
        "`place`\nmetres (rest arc length from its first point) when built. hold: 'sliding' or "
        "'sliding-turning';\nslide_min / slide_max: end stops (None: the hose's ends).")
        .def(py::init([](const std::string& scene, const std::string& node, double place,
                         const std::string& hold) {
                 formats::HoseClip c;
                 c.scene = scene;
                 c.node = node;
                 c.place = place;
                 c.hold = holdFromName(hold);
                 return c;
             }),
             py::arg("scene"), py::arg("node"), py::arg("place"), py::arg("hold") = "sliding")
        .def_readwrite("scene", &formats::HoseClip::scene, "Scene id.")
        .def_readwrite("node", &formats::HoseClip::node, "Node path, e.g. '/rig/valve'.")
        .def_readwrite(
            "place", &formats::HoseClip::place,
            "Metres of rest arc length from the hose's first point, 0 <= place <= length.")
        .def_property(
            "hold", [](const formats::HoseClip& c) { return std::string(holdName(c.hold)); },
            [](formats::HoseClip& c, const std::string& hold) { c.hold = holdFromName(hold); },
            "'sliding' or 'sliding-turning' (the hose may also turn about the clip's axis).")
        .def_readwrite("slide_min", &formats::HoseClip::slideMin,
                       "End stop (metres from the first point), or None: the hose's first point.")
        .def_readwrite("slide_max", &formats::HoseClip::slideMax,
                       "End stop (metres from the first point), or None: the hose's last point.")
        .def_property(
            "translation",
            [](const formats::HoseClip& c) { return vec3Array(c.offset.translation); },
            [](formats::HoseClip& c, const py::object& v) {
                c.offset.translation = toVec3(v, "translation");
            },
            "Offset translation in the node frame, metres.")
        .def_property(
            "rotation", [](const formats::HoseClip& c) { return quatArray(c.offset.rotation); },
            [](formats::HoseClip& c, const py::object& v) {
                c.offset.rotation = toQuat(v, "rotation");
            },
            "Offset rotation, x, y, z, w.");

    py::class_<formats::MaterialPreset>(m, "MaterialPreset",
                                        "A named material of the project (hoses refer to it by "
                                        "name).")
        .def(py::init([](const std::string& name, const Material& material,
                         const std::string& description) {
                 return formats::MaterialPreset{name, description, material};
             }),
             py::arg("name"), py::arg("material"), py::arg("description") = "")
        .def_readwrite("name", &formats::MaterialPreset::name,
                       "Unique within the project; hoses name it.")
        .def_readwrite("description", &formats::MaterialPreset::description, "For people.")
        .def_readwrite("material", &formats::MaterialPreset::material,
                       "The Material (a copy: assign a changed one).");

    py::class_<formats::PartMotion>(
        m, "Motion",
        "A moving part: a 'hinge' turns node `node` of scene `scene` by the value (radians) "
        "about `axis`\nthrough `point`; a 'slider' moves it by the value (metres) along `axis`. "
        "minimum <= 0 <= maximum.")
        .def(py::init<>(), "A hinge about +Y through the origin with an empty range (set every "
                           "field).")
        .def_readwrite("id", &formats::PartMotion::id,
                       "Unique within the project; reports name the motion by it.")
        .def_readwrite("scene", &formats::PartMotion::scene, "Scene id.")
        .def_readwrite("node", &formats::PartMotion::node,
                       "Node path of the moving part (at most one motion per node).")
        .def_property(
            "kind",
            [](const formats::PartMotion& x) { return std::string(formats::toString(x.kind)); },
            [](formats::PartMotion& x, const std::string& kind) {
                if (kind == "hinge")
                    x.kind = formats::PartMotion::Kind::Hinge;
                else if (kind == "slider")
                    x.kind = formats::PartMotion::Kind::Slider;
                else
                    throw InvalidArgument("kind: expected \"hinge\" or \"slider\", got \"" + kind +
                                          "\"");
            },
            "'hinge' or 'slider'.")
        .def_property(
            "axis", [](const formats::PartMotion& x) { return vec3Array(x.axis); },
            [](formats::PartMotion& x, const py::object& v) { x.axis = toVec3(v, "axis"); },
            "World direction at the project pose (need not be unit, length > 1e-9).")
        .def_property(
            "point", [](const formats::PartMotion& x) { return vec3Array(x.point); },
            [](formats::PartMotion& x, const py::object& v) { x.point = toVec3(v, "point"); },
            "Hinge: a world point on the axis at the project pose, metres (unused by a slider).")
        .def_readwrite("minimum", &formats::PartMotion::minimum,
                       "Radians (hinge) or metres (slider), <= 0.")
        .def_readwrite("maximum", &formats::PartMotion::maximum,
                       "Radians (hinge) or metres (slider), >= 0, > minimum.");

    py::class_<formats::HoseDefinition>(
        m, "HoseDefinition",
        "One hose of a project as its author laid it out: the route (world metres, the shape "
        "at the\nfile pose) and the length (None: as long as the hose laid along its route) "
        "are separate,\nso reshaping never changes the length. material: a preset name (str) "
        "or a Material.\nfittings_allowance: metres the end fittings take beyond the rest "
        "length (cut length =\nlength + allowance). Edits are checked by Project.validate() "
        "and Project.save() with the\nloader's rules.")
        .def(py::init([](const std::string& id, const std::string& name, const py::object& route) {
                 formats::HoseDefinition h;
                 h.id = id;
                 h.name = name;
                 h.route = toPoints(route, "route");
                 return h;
             }),
             py::arg("id"), py::arg("name"), py::arg("route"))
        .def_readwrite("id", &formats::HoseDefinition::id, "Unique within the project.")
        .def_readwrite("name", &formats::HoseDefinition::name, "For people; may repeat.")
        .def_property(
            "route", [](const formats::HoseDefinition& h) { return pointsArray(h.route); },
            [](formats::HoseDefinition& h, const py::object& v) { h.route = toPoints(v, "route"); },
            "(n, 3) world metres (a copy; assign to change).")
        .def_readwrite("length", &formats::HoseDefinition::length,
                       "Rest length in metres, or None.")
        .def_property(
            "material",
            [](const formats::HoseDefinition& h) -> py::object {
                if (const auto* preset = std::get_if<formats::PresetName>(&h.material))
                    return py::str(preset->name);
                return py::cast(std::get<Material>(h.material));
            },
            [](formats::HoseDefinition& h, const py::object& value) {
                if (py::isinstance<py::str>(value))
                    h.material = formats::PresetName{value.cast<std::string>()};
                else
                    h.material = value.cast<Material>();
            },
            "A preset name (str) or inline values (Material).")
        .def_readwrite("outer_diameter", &formats::HoseDefinition::outerDiameter, "Metres > 0.")
        .def_readwrite("segment_count", &formats::HoseDefinition::segmentCount,
                       "Axis segments (1 ... 1,000,000) when > 0, else segment_length decides.")
        .def_readwrite("segment_length", &formats::HoseDefinition::segmentLength,
                       "Target segment length in metres when segment_count is 0.")
        .def_property(
            "colour",
            [](const formats::HoseDefinition& h) {
                return py::make_tuple(h.colour.r, h.colour.g, h.colour.b, h.colour.a);
            },
            [](formats::HoseDefinition& h, const std::array<double, 4>& c) {
                h.colour = formats::Rgba{c[0], c[1], c[2], c[3]};
            },
            "Linear RGBA in [0, 1].")
        .def_readwrite("roughness", &formats::HoseDefinition::roughness, "PBR roughness in [0, 1].")
        .def_readwrite("fittings_allowance", &formats::HoseDefinition::fittingsAllowance,
                       "Metres >= 0 the end fittings take beyond the rest length, both ends.")
        .def_property(
            "attachments",
            [](formats::HoseDefinition& h) -> std::vector<formats::HoseAttachment>& {
                return h.attachments;
            },
            [](formats::HoseDefinition& h, const std::vector<formats::HoseAttachment>& list) {
                h.attachments = list;
            },
            py::return_value_policy::reference_internal,
            "The attachments (AttachmentList), in place.")
        .def_property(
            "clips",
            [](formats::HoseDefinition& h) -> std::vector<formats::HoseClip>& { return h.clips; },
            [](formats::HoseDefinition& h, const std::vector<formats::HoseClip>& list) {
                h.clips = list;
            },
            py::return_value_policy::reference_internal,
            "The clips (ClipList), in place; built after the attachments, in order.")
        .def_property(
            "gravity", [](const formats::HoseDefinition& h) { return h.gravity.enabled; },
            [](formats::HoseDefinition& h, bool on) { h.gravity.enabled = on; },
            "Gravity sag while the hose runs (direction straight down).")
        .def_property(
            "torsion", [](const formats::HoseDefinition& h) { return h.torsion.enabled; },
            [](formats::HoseDefinition& h, bool on) { h.torsion.enabled = on; },
            "Torsion on or off (twist limit 0.1 rad per joint).")
        .def("__eq__", [](const formats::HoseDefinition& a,
                          const formats::HoseDefinition& b) { return a == b; })
        .def("__repr__", [](const formats::HoseDefinition& h) {
            return "HoseDefinition(id='" + h.id + "', name='" + h.name + "')";
        });

    const char* listNote = "A list of the project's items, edited in place (items are references: "
                           "after append, insert or\ndel on the same list, fetch them again).";
    py::bind_vector<std::vector<formats::HoseDefinition>>(m, "HoseList", listNote);
    py::bind_vector<std::vector<formats::HoseAttachment>>(m, "AttachmentList", listNote);
    py::bind_vector<std::vector<formats::HoseClip>>(m, "ClipList", listNote);
    py::bind_vector<std::vector<formats::MaterialPreset>>(m, "MaterialPresetList", listNote);
    py::bind_vector<std::vector<formats::PartMotion>>(m, "MotionList", listNote);

    py::class_<PyProject>(
        m, "Project",
        "A ChainTube project (*.ctproj): scenes, material presets, hoses, poses, colliders, "
        "motions\nand export settings. Project.load reads and validates a file (errors raise "
        "ProjectFormatError\nnaming the file, the field as a JSON pointer and what was "
        "expected); edits are made on the\nobjects in place; validate() and save() check them "
        "with the loader's rules; path is the file\nthe project belongs to (relative scene "
        "paths resolve against its folder).")
        .def(py::init([](const std::string& name) {
                 return PyProject{formats::Project::withStandardPresets(name), {}, {}};
             }),
             py::arg("name") = "untitled", "An empty project with the standard material presets.")
        .def_static(
            "load",
            [](const fs::path& file,
               const std::optional<std::map<std::string, std::string>>& roots) {
                formats::ProjectLoadOptions options;
                options.roots = toRoots(roots);
                return PyProject{formats::loadProject(file, options), file, options.roots};
            },
            py::arg("path"), py::arg("roots") = py::none(),
            "Read and validate a project file. roots: {'name': 'folder'} for 'name:path' "
            "scene paths.\nRaises FileError, ProjectFormatError.")
        .def(
            "save",
            [](PyProject& p, const std::optional<fs::path>& file) {
                const fs::path target = file ? *file : p.file;
                if (target.empty())
                    throw InvalidArgument("save: expected a path (the project has none yet)");
                formats::ProjectLoadOptions options;
                options.roots = p.roots;
                formats::saveProject(p.project, target, options);
                p.file = target;
            },
            py::arg("path") = py::none(),
            "Validate (as load does) and write the canonical text atomically; path then names "
            "the file.\nRaises ProjectFormatError (nothing written) or FileError.")
        .def(
            "validate",
            [](const PyProject& p) {
                formats::ProjectLoadOptions options;
                options.roots = p.roots;
                formats::parseProject(formats::serialiseProject(p.project), p.fileForPaths(),
                                      options);
            },
            "Check the project with the loader's rules; raises ProjectFormatError naming the "
            "field.")
        .def(
            "to_json", [](const PyProject& p) { return formats::serialiseProject(p.project); },
            "The canonical file text (what save writes).")
        .def_property(
            "path",
            [](const PyProject& p) -> py::object {
                return p.file.empty() ? py::object(py::none()) : py::cast(p.file);
            },
            [](PyProject& p, const std::optional<fs::path>& file) {
                p.file = file.value_or(fs::path());
            },
            "The project file (None: not saved yet; the current folder resolves paths).")
        .def_property(
            "name", [](const PyProject& p) { return p.project.name; },
            [](PyProject& p, const std::string& name) { p.project.name = name; },
            "The project name, for people.")
        .def_property_readonly(
            "hoses",
            [](PyProject& p) -> std::vector<formats::HoseDefinition>& { return p.project.hoses; },
            py::return_value_policy::reference_internal, "The hoses (HoseList), in place.")
        .def_property_readonly(
            "material_presets",
            [](PyProject& p) -> std::vector<formats::MaterialPreset>& {
                return p.project.materialPresets;
            },
            py::return_value_policy::reference_internal,
            "The material presets (MaterialPresetList), in place.")
        .def_property_readonly(
            "motions",
            [](PyProject& p) -> std::vector<formats::PartMotion>& { return p.project.motions; },
            py::return_value_policy::reference_internal, "The moving parts (MotionList), in place.")
        .def_property_readonly(
            "scenes",
            [](const PyProject& p) {
                py::list scenes;
                for (const formats::SceneReference& scene : p.project.scenes) {
                    py::dict d;
                    d["id"] = scene.id;
                    d["path"] = scene.path;
                    scenes.append(d);
                }
                return scenes;
            },
            "The scenes as [{'id', 'path'}] (a copy).")
        .def(
            "hose",
            [](PyProject& p, const std::string& id) -> formats::HoseDefinition& {
                for (formats::HoseDefinition& hose : p.project.hoses)
                    if (hose.id == id) return hose;
                throw py::key_error("no hose with id '" + id + "'");
            },
            py::arg("id"), py::return_value_policy::reference_internal,
            "The hose with this id (KeyError when there is none).")
        .def(
            "build_hose",
            [](const PyProject& p, const std::string& id) {
                for (const formats::HoseDefinition& hose : p.project.hoses)
                    if (hose.id == id) {
                        const formats::ImportedScenes scenes =
                            formats::importProjectScenes(p.project, p.fileForPaths(), p.roots);
                        return PyHose(formats::buildHose(p.project, hose, scenes));
                    }
                throw py::key_error("no hose with id '" + id + "'");
            },
            py::arg("id"),
            "The hose built as the export builds it (scenes imported, attachments fixed, "
            "poses followed).")
        .def("__eq__",
             [](const PyProject& a, const PyProject& b) { return a.project == b.project; })
        .def("__repr__", [](const PyProject& p) {
            return "Project(name='" + p.project.name +
                   "', hoses=" + std::to_string(p.project.hoses.size()) + ")";
        });

    // --- export, checks, report ---------------------------------------------------------------
    m.def(
        "export",
        [](const PyProject& p, const fs::path& output) {
            if (output.has_parent_path()) fs::create_directories(output.parent_path());
            const exporting::ExportReport report =
                exporting::exportProject(p.project, p.fileForPaths(), output, p.roots);
            py::dict d;
            d["gltf_file"] = report.gltfFile;
            d["bin_file"] =
                report.binFile.empty() ? py::object(py::none()) : py::cast(report.binFile);
            d["descriptor_file"] = report.descriptorFile.empty() ? py::object(py::none())
                                                                 : py::cast(report.descriptorFile);
            d["hose_count"] = report.hoseCount;
            d["joint_count"] = report.jointCount;
            d["scene_node_count"] = report.sceneNodeCount;
            d["bytes_written"] = report.bytesWritten;
            d["warnings"] = report.warnings;
            return d;
        },
        py::arg("project"), py::arg("path"),
        "Export the project to `path` (.glb, or .gltf + .bin) with its runtime descriptor "
        "<name>.hoses.json\nbeside it: the export `chaintube export PROJECT -o PATH` writes, "
        "byte for byte. Returns\n{gltf_file, bin_file, descriptor_file, hose_count, "
        "joint_count, scene_node_count, bytes_written,\nwarnings}.");

    m.def(
        "check",
        [](const PyProject& p, bool sweep, double clearance, int steps, bool includeAttached) {
            if (!sweep) {
                exporting::ClearanceOptions options;
                options.threshold = clearance;
                options.includeAttachedNodes = includeAttached;
                const formats::ImportedScenes scenes =
                    formats::importProjectScenes(p.project, p.fileForPaths(), p.roots);
                std::vector<Hose> hoses;
                for (const formats::HoseDefinition& definition : p.project.hoses) {
                    Hose hose = formats::buildHose(p.project, definition, scenes);
                    formats::settleUnderGravity(hose, definition, p.project, scenes);
                    hoses.push_back(std::move(hose));
                }
                py::list violations;
                for (const exporting::ClearanceFinding& v : exporting::clearanceViolations(
                         p.project, hoses, exporting::sceneObjects(p.project, scenes), options)) {
                    py::dict d;
                    d["hose"] = v.hoseId;
                    d["scene"] = v.sceneId;
                    d["object"] = v.objectPath;
                    d["distance"] = v.distance;
                    d["axis_point"] = v.axisPoint;
                    d["on_hose"] = vec3Array(v.onHose);
                    d["on_object"] = vec3Array(v.onObject);
                    violations.append(d);
                }
                py::dict result;
                result["clearance_threshold"] = clearance;
                result["violations"] = violations;
                return result;
            }
            exporting::SweepOptions options;
            options.steps = steps;
            options.clearanceThreshold = clearance;
            options.includeAttachedNodes = includeAttached;
            const formats::ImportedScenes scenes =
                p.project.motions.empty()
                    ? formats::ImportedScenes()
                    : formats::importProjectScenes(p.project, p.fileForPaths(), p.roots);
            return sweepDict(exporting::sweepMotions(p.project, scenes, options));
        },
        py::arg("project"), py::arg("sweep") = true, py::arg("clearance") = 0.0,
        py::arg("steps") = 20, py::arg("include_attached") = false,
        "sweep=True: `chaintube check --sweep` as data: every motion driven through its range "
        "and back\n(steps each way), per hose the worst stretch, the smallest bend radius, the "
        "clearance to each\nobject and the updates that were not Ok, each with its step "
        "({index, phase, t, values}).\nA project without motions gives steps 0 and no hoses. "
        "sweep=False: `chaintube check\n--clearance` as data: {'violations': [...]} closer "
        "than `clearance` metres.");

    m.def(
        "fit_length",
        [](const PyProject& p, const std::vector<std::string>& hoses, int steps, double tolerance,
           double clearance) {
            exporting::LengthFitOptions options;
            options.steps = steps;
            options.tolerance = tolerance;
            options.clearanceThreshold = clearance;
            const formats::ImportedScenes scenes =
                formats::importProjectScenes(p.project, p.fileForPaths(), p.roots);
            py::list fits;
            for (const exporting::LengthFit& fit :
                 exporting::fitLengths(p.project, scenes, hoses, options).hoses)
                fits.append(fitDict(fit));
            return fits;
        },
        py::arg("project"), py::arg("hoses") = std::vector<std::string>(), py::arg("steps") = 20,
        py::arg("tolerance") = 0.001, py::arg("clearance") = 0.0,
        "`chaintube check --fit-length` as data: for each hose between fixed ends (or those "
        "named by\nid), the range of lengths valid over the motions: [{hose, current_length, "
        "valid, shortest,\nlongest, shortest_limit, longest_limit, ...}].");

    m.def(
        "report",
        [](const py::object& source, std::optional<std::string> format, int steps, double clearance,
           bool fitLength,
           const std::optional<std::map<std::string, std::string>>& roots) -> py::object {
            exporting::ReportOptions options;
            options.steps = steps;
            options.clearanceThreshold = clearance;
            options.fitLength = fitLength;
            exporting::LengthReport report;
            const auto add = [&](const py::handle& item) {
                exporting::LengthReport one;
                if (py::isinstance<PyProject>(item)) {
                    const PyProject& p = item.cast<const PyProject&>();
                    one = exporting::projectReport(p.project, p.fileForPaths(), p.roots, options);
                } else {
                    one = exporting::reportProjects(exporting::reportSources(item.cast<fs::path>()),
                                                    toRoots(roots), options);
                }
                for (std::string& project : one.projects)
                    report.projects.push_back(std::move(project));
                for (exporting::HoseReport& hose : one.hoses)
                    report.hoses.push_back(std::move(hose));
            };
            if (py::isinstance<py::list>(source) || py::isinstance<py::tuple>(source))
                for (const py::handle item : source)
                    add(item);
            else
                add(source);
            report.materials = exporting::materialTotals(report.hoses);
            if (format)
                return py::str(
                    exporting::formatReport(report, exporting::reportFormatFromName(*format)));
            return reportDict(report);
        },
        py::arg("source"), py::arg("format") = py::none(), py::arg("steps") = 20,
        py::arg("clearance") = 0.0, py::arg("fit_length") = true, py::arg("roots") = py::none(),
        "The length and bill-of-materials report (`chaintube report`) of a Project, a project "
        "file, a\nfolder of them, or a list of these. format None: a dict {projects, hoses, "
        "materials}, each hose\n{id, name, material, rest_length, fittings_allowance, "
        "cut_length, shortest_valid_length, slack,\nsmallest_bend_radius, min_bend_radius, "
        "bend_margin, smallest_clearance, clearance_object,\nclearance_axis_point, "
        "clearance_point, clearance_motion, attachments, clips} (None where absent),\neach "
        "material {material, hoses, rest_length, fittings_allowance, cut_length}; "
        "format 'csv',\n'json' or 'md': the text the CLI writes. Lengths in metres.");

    m.def(
        "find_projects",
        [](const std::string& folderOrPattern) { return exporting::findProjects(folderOrPattern); },
        py::arg("folder_or_pattern"),
        "The project files in a folder (*.ctproj directly in it) or matching a glob pattern, "
        "sorted.");
}

} // namespace chaintube::python
