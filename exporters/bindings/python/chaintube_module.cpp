// The Python module `chaintube`: projects, export, checks, the length report, the model and the
// runtime, over the same functions the CLI and the editor call (formats/, exporters/, lib/).
// One translation unit: pybind11 and Eigen are parsed once; tinygltf, CLI11 and nlohmann-json
// stay out (they are private to the libraries). Guide: exporters/bindings/python/README.md.
#include <chaintube/export/batch.h>
#include <chaintube/export/clearance.h>
#include <chaintube/export/fit_length.h>
#include <chaintube/export/gltf_export.h>
#include <chaintube/export/report.h>
#include <chaintube/export/rig_descriptor.h>
#include <chaintube/export/runtime.h>
#include <chaintube/export/sweep.h>
#include <chaintube/formats/errors.h>
#include <chaintube/formats/paths.h>
#include <chaintube/formats/project.h>
#include <chaintube/formats/project_hoses.h>
#include <chaintube/hose.h>
#include <cmath>
#include <cstdlib>
#include <dlfcn.h>
#include <filesystem>
#include <limits>
#include <optional>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <pybind11/stl_bind.h>
#include <string>
#include <variant>
#include <vector>

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace chaintube;

PYBIND11_MAKE_OPAQUE(std::vector<formats::HoseDefinition>)
PYBIND11_MAKE_OPAQUE(std::vector<formats::HoseAttachment>)
PYBIND11_MAKE_OPAQUE(std::vector<formats::HoseClip>)
PYBIND11_MAKE_OPAQUE(std::vector<formats::MaterialPreset>)
PYBIND11_MAKE_OPAQUE(std::vector<formats::PartMotion>)

namespace {

// --- conversions ------------------------------------------------------------------------------

Vec3 toVec3(const py::handle& value, const char* what)
{
    const py::array_t<double, py::array::c_style | py::array::forcecast> array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!array || array.size() != 3)
        throw InvalidArgument(std::string(what) + ": expected 3 numbers (x, y, z)");
    return Vec3(array.data()[0], array.data()[1], array.data()[2]);
}

Quat toQuat(const py::handle& value, const char* what)
{
    const auto array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!array || array.size() != 4)
        throw InvalidArgument(std::string(what) + ": expected 4 numbers (x, y, z, w)");
    const double* q = array.data();
    return Quat(q[3], q[0], q[1], q[2]);
}

py::array_t<double> vec3Array(const Vec3& v)
{
    py::array_t<double> array(3);
    for (int k = 0; k < 3; ++k)
        array.mutable_data()[k] = v[k];
    return array;
}

py::array_t<double> quatArray(const Quat& q)
{
    py::array_t<double> array(4);
    double* out = array.mutable_data();
    out[0] = q.x();
    out[1] = q.y();
    out[2] = q.z();
    out[3] = q.w();
    return array;
}

/// An (n, 3) array (a copy) of points.
py::array_t<double> pointsArray(const std::vector<Vec3>& points)
{
    py::array_t<double> array({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
    double* out = array.mutable_data();
    for (size_t i = 0; i < points.size(); ++i)
        for (int k = 0; k < 3; ++k)
            out[3 * i + static_cast<size_t>(k)] = points[i][k];
    return array;
}

std::vector<Vec3> toPoints(const py::handle& value, const char* what)
{
    const auto array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!array || array.ndim() != 2 || array.shape(1) != 3)
        throw InvalidArgument(std::string(what) + ": expected an (n, 3) array of points");
    std::vector<Vec3> points;
    const double* in = array.data();
    for (py::ssize_t i = 0; i < array.shape(0); ++i)
        points.emplace_back(in[3 * i], in[3 * i + 1], in[3 * i + 2]);
    return points;
}

formats::NamedRoots toRoots(const std::optional<std::map<std::string, std::string>>& roots)
{
    formats::NamedRoots result;
    if (roots)
        for (const auto& [name, folder] : *roots)
            result[name] = folder;
    return result;
}

py::object optionalFloat(double value)
{
    return std::isfinite(value) ? py::object(py::float_(value)) : py::object(py::none());
}

// --- exceptions ---------------------------------------------------------------------------------

struct ExceptionTypes
{
    PyObject* error = nullptr;
    PyObject* invalidArgument = nullptr;
    PyObject* fileError = nullptr;
    PyObject* projectFormatError = nullptr;
    PyObject* sceneImportError = nullptr;
    PyObject* cancelled = nullptr;
    PyObject* pathError = nullptr;
    PyObject* descriptorError = nullptr;
    PyObject* unreadableFile = nullptr;
};
ExceptionTypes exceptions;

PyObject* newException(py::module_& m, const char* name, const char* doc, PyObject* bases)
{
    const std::string qualified = std::string("chaintube.") + name;
    PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases, nullptr);
    if (!type) throw py::error_already_set();
    m.add_object(name, py::handle(type));
    return type;
}

/// Raises `type` with `message` and the given attributes set on the exception object.
void raise(PyObject* type, const std::string& message,
           std::initializer_list<std::pair<const char*, py::object>> attributes)
{
    py::object instance =
        py::reinterpret_steal<py::object>(PyObject_CallFunction(type, "s", message.c_str()));
    if (!instance) return; // the call set an error
    for (const auto& [name, value] : attributes)
        instance.attr(name) = value;
    PyErr_SetObject(type, instance.ptr());
}

void translateException(std::exception_ptr pointer)
{
    try {
        std::rethrow_exception(pointer);
    } catch (const formats::ProjectFormatError& e) {
        raise(exceptions.projectFormatError, e.what(),
              {{"file", py::str(e.file().string())},
               {"reason", py::str(e.reason())},
               {"json_pointer", py::str(e.jsonPointer())},
               {"expected", py::str(e.expected())}});
    } catch (const formats::ImportError& e) {
        raise(exceptions.sceneImportError, e.what(),
              {{"file", py::str(e.file().string())},
               {"reason", py::str(e.reason())},
               {"signal", py::int_(e.signal())}});
    } catch (const formats::FileError& e) {
        raise(exceptions.fileError, e.what(),
              {{"file", py::str(e.file().string())}, {"reason", py::str(e.reason())}});
    } catch (const formats::Cancelled& e) {
        raise(exceptions.cancelled, e.what(), {});
    } catch (const formats::PathError& e) {
        raise(exceptions.pathError, e.what(),
              {{"path", py::str(e.written())}, {"reason", py::str(e.reason())}});
    } catch (const rig::DescriptorError& e) {
        raise(exceptions.descriptorError, e.what(),
              {{"file", py::str(e.source())}, {"json_pointer", py::str(e.pointer())}});
    } catch (const rig::UnreadableFile& e) {
        raise(exceptions.unreadableFile, e.what(), {});
    } catch (const InvalidArgument& e) {
        raise(exceptions.invalidArgument, e.what(), {});
    } catch (const Error& e) {
        raise(exceptions.error, e.what(), {});
    }
}

// --- wrapped state ------------------------------------------------------------------------------

/// A project and the file it belongs to (relative scene paths resolve against its folder).
struct PyProject
{
    formats::Project project;
    fs::path file; ///< empty: not saved yet (the current folder resolves paths)
    formats::NamedRoots roots;
    fs::path fileForPaths() const
    {
        return file.empty() ? fs::current_path() / "untitled.ctproj" : file;
    }
};

/// A hose with a world-coordinate copy of its axis that every call through Python keeps up to
/// date: Hose.points is a view of that buffer (no copy per access; the same memory for the
/// hose's life, as the point count of a hose never changes).
struct PyHose
{
    explicit PyHose(Hose built) : hose(std::move(built)), world(3 * hose.pointCount())
    {
        refresh();
    }
    void refresh()
    {
        const Vec3& origin = hose.origin();
        const std::vector<Vec3>& local = hose.localPoints();
        for (size_t i = 0; i < local.size(); ++i)
            for (int k = 0; k < 3; ++k)
                world[3 * i + static_cast<size_t>(k)] = origin[k] + local[i][k];
    }
    Hose hose;
    std::vector<double> world;
};

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

const char* holdName(Hold hold)
{
    return toString(hold);
}

Hold holdFromName(const std::string& name)
{
    if (name == toString(Hold::Sliding)) return Hold::Sliding;
    if (name == toString(Hold::SlidingTurning)) return Hold::SlidingTurning;
    throw InvalidArgument("hold: expected \"" + std::string(toString(Hold::Sliding)) + "\" or \"" +
                          toString(Hold::SlidingTurning) + "\", got \"" + name + "\"");
}

/// A rigid frame from a translation and an (x, y, z, w) rotation.
Frame frameOf(const py::handle& translation, const py::handle& rotation)
{
    return Frame{toQuat(rotation, "rotation"), toVec3(translation, "translation")};
}

/// Scene import runs reader programs (formats/README.md, "The reader processes"). An installed
/// wheel ships them in chaintube_readers/ beside the module: point CHAINTUBE_READERS_DIR there
/// unless it is set. In the build tree there is no such folder and the programs are found where
/// they were built.
void findShippedReaders()
{
    if (const char* chosen = std::getenv("CHAINTUBE_READERS_DIR"); chosen && *chosen) return;
    Dl_info info{};
    if (::dladdr(reinterpret_cast<void*>(&findShippedReaders), &info) == 0 || !info.dli_fname)
        return;
    std::error_code ignored;
    const fs::path readers = fs::path(info.dli_fname).parent_path() / "chaintube_readers";
    if (fs::is_directory(readers, ignored)) ::setenv("CHAINTUBE_READERS_DIR", readers.c_str(), 0);
}

} // namespace

PYBIND11_MODULE(chaintube, m)
{
    findShippedReaders();
    m.doc() =
        "ChainTube: deformable hoses and cables for VR training scenes.\n\n"
        "The same code the `chaintube` command line and the editor call: projects (*.ctproj) "
        "are\nloaded, edited, validated and saved (Project), exported as glTF hose rigs "
        "(export),\nchecked (check, fit_length) and reported (report: cut lengths and the bill "
        "of materials);\nthe model runs hoses directly (Hose) and the runtime runs an export "
        "(Rig).\n\nUnits: metres, radians; positions are world coordinates, +Y up. Errors "
        "raise\nchaintube.Error and its subclasses with the library's message (file, field, "
        "expectation).";

    // --- exceptions -------------------------------------------------------------------------
    exceptions.error =
        newException(m, "Error", "Root of every ChainTube error (chaintube::Error).", nullptr);
    {
        py::tuple bases =
            py::make_tuple(py::handle(exceptions.error), py::handle(PyExc_ValueError));
        exceptions.invalidArgument =
            newException(m, "InvalidArgument",
                         "A value outside the documented domain of a set-up function; the "
                         "message names the parameter and what was expected.",
                         bases.ptr());
    }
    exceptions.fileError = newException(
        m, "FileError",
        "A file could not be read, written or understood. Attributes: file, reason; str() is "
        "'<file>: <reason>'.",
        exceptions.error);
    exceptions.projectFormatError = newException(
        m, "ProjectFormatError",
        "A project document is malformed. Attributes: file, json_pointer (the field, e.g. "
        "'/hoses/0/length'), expected; str() is '<file>: <pointer>: <expected>'.",
        exceptions.fileError);
    exceptions.sceneImportError = newException(
        m, "SceneImportError",
        "The reader process of a scene file crashed. Attributes: file, reason, signal.",
        exceptions.fileError);
    exceptions.cancelled =
        newException(m, "Cancelled", "A progress callback asked to stop.", exceptions.error);
    exceptions.pathError = newException(
        m, "PathError",
        "A project path escapes the project folder or names an unknown root. Attributes: path, "
        "reason.",
        exceptions.error);
    exceptions.descriptorError =
        newException(m, "DescriptorError",
                     "A hose-rig descriptor is malformed. Attributes: file, json_pointer; str() is "
                     "'<file>: <pointer>: <expected>'.",
                     exceptions.error);
    exceptions.unreadableFile = newException(
        m, "UnreadableFile", "A file of an export cannot be read (missing or no permission).",
        exceptions.error);
    py::register_exception_translator(translateException);

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
