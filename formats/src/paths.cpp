#include "chaintube/formats/paths.h"

#include <cctype>
#include <system_error>
#include <utility>

namespace chaintube::formats {

namespace fs = std::filesystem;

PathError::PathError(std::string written, std::string reason)
    : Error("path \"" + written + "\": " + reason), m_written(std::move(written)),
      m_reason(std::move(reason))
{
}

namespace {

/// Length of the root name before ':' if `written` starts with a named root, else 0.
size_t namedRootLength(std::string_view written)
{
    const size_t colon = written.find(':');
    if (colon == std::string_view::npos || colon < 2) return 0;
    if (!std::isalpha(static_cast<unsigned char>(written[0]))) return 0;
    for (size_t i = 1; i < colon; ++i) {
        const unsigned char c = static_cast<unsigned char>(written[i]);
        if (!std::isalnum(c) && c != '_' && c != '-') return 0;
    }
    return colon;
}

fs::path canonicalOrThrow(const fs::path& path, std::string_view written)
{
    std::error_code error;
    fs::path result = fs::weakly_canonical(path, error);
    if (error) throw PathError(std::string(written), "cannot be resolved: " + error.message());
    return result;
}

} // namespace

PathKind classifyProjectPath(std::string_view written)
{
    if (written.empty()) throw PathError("", "is empty");
    if (written.find('\0') != std::string_view::npos)
        throw PathError(std::string(written), "contains a NUL character");
    if (written.find('\\') != std::string_view::npos)
        throw PathError(std::string(written), "contains '\\'; write paths with '/'");
    if (namedRootLength(written) > 0) return PathKind::NamedRoot;
    return fs::path(std::string(written)).is_absolute() ? PathKind::Absolute : PathKind::Relative;
}

bool isInsideFolder(const fs::path& path, const fs::path& folder)
{
    std::error_code error;
    const fs::path canonicalPath = fs::weakly_canonical(path, error);
    if (error) return false;
    const fs::path canonicalFolder = fs::weakly_canonical(folder, error);
    if (error) return false;
    auto p = canonicalPath.begin();
    for (auto f = canonicalFolder.begin(); f != canonicalFolder.end(); ++f, ++p) {
        if (f->empty()) continue; // trailing separator of the folder
        if (p == canonicalPath.end() || *p != *f) return false;
    }
    return true;
}

fs::path resolveProjectPath(std::string_view written, const fs::path& projectDirectory,
                            const NamedRoots& roots)
{
    const std::string text(written);
    switch (classifyProjectPath(written)) {
    case PathKind::Absolute:
        return canonicalOrThrow(fs::path(text), written);
    case PathKind::Relative: {
        const fs::path base = fs::absolute(projectDirectory);
        const fs::path resolved = canonicalOrThrow(base / text, written);
        if (!isInsideFolder(resolved, base))
            throw PathError(text, "leaves the project's folder " + base.string() +
                                      " (resolves to " + resolved.string() +
                                      "); write an absolute path or use a named root");
        return resolved;
    }
    case PathKind::NamedRoot: {
        const size_t colon = namedRootLength(written);
        const std::string rootName = text.substr(0, colon);
        const std::string rest = text.substr(colon + 1);
        const auto root = roots.find(rootName);
        if (root == roots.end()) {
            std::string known;
            for (const auto& [name, folder] : roots)
                known += (known.empty() ? "" : ", ") + name;
            throw PathError(text, "unknown named root '" + rootName +
                                      "' (known: " + (known.empty() ? "none" : known) + ")");
        }
        if (rest.empty() || fs::path(rest).is_absolute())
            throw PathError(text, "expected a relative path after '" + rootName + ":'");
        const fs::path base = fs::absolute(root->second);
        const fs::path resolved = canonicalOrThrow(base / rest, written);
        if (!isInsideFolder(resolved, base))
            throw PathError(text, "leaves the root '" + rootName + "' (" + base.string() +
                                      "; resolves to " + resolved.string() + ")");
        return resolved;
    }
    }
    throw PathError(text, "unknown kind of path");
}

namespace {

/// `file` (canonical) written relative to `folder` (canonical), which contains it.
std::string relativeInside(const fs::path& file, const fs::path& folder)
{
    const fs::path relative = file.lexically_relative(folder);
    return relative.empty() ? std::string(".") : relative.generic_string();
}

bool sameFolder(const fs::path& a, const fs::path& b)
{
    std::error_code error;
    const fs::path ca = fs::weakly_canonical(fs::absolute(a), error);
    if (error) return false;
    const fs::path cb = fs::weakly_canonical(fs::absolute(b), error);
    return !error && ca == cb;
}

} // namespace

std::string projectPathFor(const fs::path& file, const fs::path& projectDirectory,
                           const NamedRoots& roots)
{
    const fs::path absolute = fs::absolute(file);
    std::error_code error;
    const fs::path canonical = fs::weakly_canonical(absolute, error);
    if (error) return absolute.lexically_normal().generic_string();
    if (!projectDirectory.empty()) {
        const fs::path canonicalFolder =
            fs::weakly_canonical(fs::absolute(projectDirectory), error);
        if (!error && isInsideFolder(canonical, canonicalFolder) && canonical != canonicalFolder)
            return relativeInside(canonical, canonicalFolder);
    }
    for (const auto& [name, root] : roots) {
        const fs::path canonicalRoot = fs::weakly_canonical(fs::absolute(root), error);
        if (!error && isInsideFolder(canonical, canonicalRoot) && canonical != canonicalRoot)
            return name + ":" + relativeInside(canonical, canonicalRoot);
    }
    return canonical.generic_string();
}

std::string rebaseProjectPath(std::string_view written, const fs::path& fromDirectory,
                              const fs::path& toDirectory)
{
    const PathKind kind = classifyProjectPath(written);
    if (kind == PathKind::NamedRoot || sameFolder(fromDirectory, toDirectory))
        return std::string(written);
    if (kind == PathKind::Absolute) {
        const std::string relative =
            projectPathFor(fs::path(std::string(written)), toDirectory, {});
        // Kept as written unless the file lies in the new folder.
        return classifyProjectPath(relative) == PathKind::Relative ? relative
                                                                   : std::string(written);
    }
    const fs::path file = resolveProjectPath(written, fromDirectory, {});
    return projectPathFor(file, toDirectory, {});
}

} // namespace chaintube::formats
