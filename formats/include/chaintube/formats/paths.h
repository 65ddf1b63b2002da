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

/// True if `path` is `folder` or inside it, comparing weakly_canonical forms component-wise.
bool isInsideFolder(const std::filesystem::path& path, const std::filesystem::path& folder);

} // namespace chaintube::formats
