// The Python module `chaintube`: projects, export, checks, the length report, the model and the
// runtime, over the same functions the CLI and the editor call (formats/, exporters/, lib/).
// This unit makes the module and its exceptions; bind_model.cpp, bind_project.cpp and
// bind_runtime.cpp add the classes and functions. tinygltf, CLI11 and nlohmann-json stay out
// (they are private to the libraries). Guide: exporters/bindings/python/README.md.
#include "module_support.h"

#include <cstdlib>
#include <dlfcn.h>

using namespace chaintube;
using namespace chaintube::python;

namespace {

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

    bindModel(m);
    bindProject(m);
    bindRuntime(m);
}
