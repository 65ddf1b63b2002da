// What the translation units of the Python module `chaintube` share: conversions between
// Python values and the library's types, the objects Python holds (a project with its file, a
// hose with a world copy of its axis) and the functions each unit adds to the module.
#pragma once

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

PYBIND11_MAKE_OPAQUE(std::vector<chaintube::formats::HoseDefinition>)
PYBIND11_MAKE_OPAQUE(std::vector<chaintube::formats::HoseAttachment>)
PYBIND11_MAKE_OPAQUE(std::vector<chaintube::formats::HoseClip>)
PYBIND11_MAKE_OPAQUE(std::vector<chaintube::formats::MaterialPreset>)
PYBIND11_MAKE_OPAQUE(std::vector<chaintube::formats::PartMotion>)

namespace chaintube::python {

namespace py = pybind11;
namespace fs = std::filesystem;

// --- conversions ------------------------------------------------------------------------------

inline Vec3 toVec3(const py::handle& value, const char* what)
{
    const py::array_t<double, py::array::c_style | py::array::forcecast> array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!array || array.size() != 3)
        throw InvalidArgument(std::string(what) + ": expected 3 numbers (x, y, z)");
    return Vec3(array.data()[0], array.data()[1], array.data()[2]);
}

inline Quat toQuat(const py::handle& value, const char* what)
{
    const auto array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!array || array.size() != 4)
        throw InvalidArgument(std::string(what) + ": expected 4 numbers (x, y, z, w)");
    const double* q = array.data();
    return Quat(q[3], q[0], q[1], q[2]);
}

inline py::array_t<double> vec3Array(const Vec3& v)
{
    py::array_t<double> array(3);
    for (int k = 0; k < 3; ++k)
        array.mutable_data()[k] = v[k];
    return array;
}

inline py::array_t<double> quatArray(const Quat& q)
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
inline py::array_t<double> pointsArray(const std::vector<Vec3>& points)
{
    py::array_t<double> array({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
    double* out = array.mutable_data();
    for (size_t i = 0; i < points.size(); ++i)
        for (int k = 0; k < 3; ++k)
            out[3 * i + static_cast<size_t>(k)] = points[i][k];
    return array;
}

inline std::vector<Vec3> toPoints(const py::handle& value, const char* what)
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

inline formats::NamedRoots toRoots(const std::optional<std::map<std::string, std::string>>& roots)
{
    formats::NamedRoots result;
    if (roots)
        for (const auto& [name, folder] : *roots)
            result[name] = folder;
    return result;
}

inline py::object optionalFloat(double value)
{
    return std::isfinite(value) ? py::object(py::float_(value)) : py::object(py::none());
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

inline const char* holdName(Hold hold)
{
    return toString(hold);
}

inline Hold holdFromName(const std::string& name)
{
    if (name == toString(Hold::Sliding)) return Hold::Sliding;
    if (name == toString(Hold::SlidingTurning)) return Hold::SlidingTurning;
    throw InvalidArgument("hold: expected \"" + std::string(toString(Hold::Sliding)) + "\" or \"" +
                          toString(Hold::SlidingTurning) + "\", got \"" + name + "\"");
}

/// A rigid frame from a translation and an (x, y, z, w) rotation.
inline Frame frameOf(const py::handle& translation, const py::handle& rotation)
{
    return Frame{toQuat(rotation, "rotation"), toVec3(translation, "translation")};
}

/// Status, UpdateResult, Material, HoseSpec and Hose: the model run directly.
void bindModel(py::module_& m);
/// Project and its items, export, check, sweep, fit_length, report and find_projects.
void bindProject(py::module_& m);
/// Rig: the runtime running an export.
void bindRuntime(py::module_& m);

} // namespace chaintube::python
