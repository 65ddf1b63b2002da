// ChainTube export — checking and describing project, descriptor and glTF files (the CLI's
// `validate` and `info`, an editor's "check export").
#pragma once

#include "chaintube/formats/paths.h"

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace chaintube::exporting {

enum class FileKind {
    Project,    ///< *.ctproj
    Descriptor, ///< *.hoses.json (or any .json with "format": "chaintube-hose-rig")
    Gltf,       ///< *.glb, *.gltf
};

/// The kind of a file from its name (.ctproj, .json, .glb, .gltf). Throws InvalidArgument
/// naming the file for any other extension.
FileKind fileKindOf(const std::filesystem::path& file);

struct ValidationResult
{
    FileKind kind = FileKind::Project;
    /// Each message starts with the file and names the field (JSON pointer) where it can.
    std::vector<std::string> errors;
    /// Hose-state findings that do not make the file invalid: overstretch, bend radius below
    /// the minimum, ring self-intersection.
    std::vector<std::string> warnings;
    bool valid() const { return errors.empty(); }
};

/// Checks a file completely; never throws for problems in the file (they become errors).
///  * Project: the project schema and references (formats::loadProject), its scenes import
///    (paths resolved with `roots`), every hose builds and its attachments resolve.
///  * Descriptor: the descriptor schema (types, ranges, version), hose invariants (array lengths,
///    attachment ranges, grabbable points free, axis within the stretch band of the rest
///    lengths, per-joint limits consistent with the bend limit).
///  * glTF/GLB: the descriptor as above; the extension in extensionsUsed and not in
///    extensionsRequired; buffers and accessors readable; per hose a skinned mesh node at the
///    scene root whose skin lists the descriptor's joints in axis order; joints are TRS nodes;
///    every joint's world transform equals the hose's ring frame (1e-4 m / 1e-4 rad), and
///    descriptor node indices exist. A sidecar <name>.hoses.json, if present, must equal the
///    embedded descriptor.
ValidationResult validateFile(const std::filesystem::path& file, const formats::NamedRoots& roots);

/// Writes a human-readable description of a file: the collider objects (project: scene and
/// node path; descriptor/glTF: node index and name), then per hose its name, points, rest and
/// current length, material, diameter and cross-section, colour, gravity (on/off, world
/// direction), torsion (on/off, twist limit in radians and degrees per joint), attachments,
/// and the warnings (overstretch, bend below minimum, ring self-intersection). Returns the
/// number of warnings.
/// Throws chaintube::Error (naming the file) if the file cannot be read or is invalid.
int describeFile(const std::filesystem::path& file, const formats::NamedRoots& roots,
                 std::ostream& out);

} // namespace chaintube::exporting
