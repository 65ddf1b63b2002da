// ChainTube formats — resolving the file paths written in a project.
#pragma once

#include "chaintube/formats/errors.h"

#include <filesystem>
#include <map>
#include <string>
#include <string_view>

namespace chaintube::formats {

/// Named roots for shared asset libraries: a project path "scenes:engine/2Cyl.glb" resolves to
/// roots.at("scenes") / "engine/2Cyl.glb". The caller supplies the map (the CLI from
/// --root scenes=<dir>, tests from CHAINTUBE_SCENES_DIR); the project only stores the name.
using NamedRoots = std::map<std::string, std::filesystem::path>;

/// A path written in a project cannot be used. what() is "<written>: <reason>".
class PathError : public Error
{
public:
    PathError(std::string written, std::string reason);
    const std::string& written() const { return m_written; }
    const std::string& reason() const { return m_reason; }

private:
    std::string m_written;
    std::string m_reason;
};

/// The three forms a project path can take.
enum class PathKind {
    Relative,  ///< "scenes/rig.gltf": relative to the project file's folder, must stay inside it
    Absolute,  ///< "/data/cad/rig.step": the user wrote it so; used as is
    NamedRoot, ///< "scenes:rig.gltf": relative to a caller-supplied root, must stay inside it
};

/// Classifies a written path. A named root is 2+ characters [A-Za-z][A-Za-z0-9_-]+ before ':'
/// (so a Windows drive "C:" is not one). Throws PathError for an empty path, a NUL character
/// or a backslash (paths are written with '/', portable between systems).
PathKind classifyProjectPath(std::string_view written);

/// Resolves a written path to an absolute, normalised file path.
///
/// Relative paths are resolved against projectDirectory, named-root paths against their root;
/// both must stay inside that folder after std::filesystem::weakly_canonical, i.e. after
/// "../" is folded and every existing symbolic link is followed (a link inside the project
/// that points outside is refused). Absolute paths are returned normalised and unchecked.
/// Throws PathError when the path escapes, names an unknown root (the message lists the
/// known ones), or a named-root path is itself absolute.
std::filesystem::path resolveProjectPath(std::string_view written,
                                         const std::filesystem::path& projectDirectory,
                                         const NamedRoots& roots);

/// How a project in `projectDirectory` writes the file `file`: a relative path when the file
/// lies inside the project's folder, else "root:rest" when it lies inside a named root (the
/// first in the map's order), else the absolute path (also when projectDirectory is empty: an
/// untitled project has no folder yet). Always written with '/'. The inside tests are
/// those of resolveProjectPath (weakly_canonical, links followed), so the written path resolves
/// back to `file` with the same roots. A relative `file` is taken against the current directory.
std::string projectPathFor(const std::filesystem::path& file,
                           const std::filesystem::path& projectDirectory, const NamedRoots& roots);

/// A written path re-expressed for a project file moving from `fromDirectory` to `toDirectory`
/// (Save As), so that it names the same file:
///  * relative: the file it names (resolved against fromDirectory) written relative to
///    toDirectory when it lies inside it, else absolute (another folder, another root);
///  * absolute: made relative when the file lies inside toDirectory (a project saved away and
///    back gets its relative paths back), else kept as written;
///  * named root: kept as written (the root is the caller's, not the folder's).
/// The file need not exist. Returns `written` unchanged when both folders are the same folder.
/// Throws PathError as classifyProjectPath(), and as resolveProjectPath() for a relative path
/// that leaves fromDirectory.
std::string rebaseProjectPath(std::string_view written, const std::filesystem::path& fromDirectory,
                              const std::filesystem::path& toDirectory);

/// True if `path` is `folder` or inside it, comparing weakly_canonical forms component-wise.
bool isInsideFolder(const std::filesystem::path& path, const std::filesystem::path& folder);

} // namespace chaintube::formats
