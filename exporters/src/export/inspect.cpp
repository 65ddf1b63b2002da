#include "chaintube/export/inspect.h"

#include "../runtime/gltf_container.h"
#include "chaintube/export/gltf_export.h"
#include "chaintube/export/runtime.h"
#include "chaintube/formats/project_hoses.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

namespace chaintube::exporting {

namespace {

namespace fs = std::filesystem;

std::string lower(std::string text)
{
    std::transform(text.begin(), text.end(), text.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return text;
}

/// Hose invariants a parsed descriptor must meet beyond its schema.
void checkDescriptorHoses(const rig::HoseRigDescriptor& descriptor, const std::string& source,
                          ValidationResult& result)
{
    for (size_t h = 0; h < descriptor.hoses.size(); ++h) {
        const rig::RigHose& d = descriptor.hoses[h];
        const std::string at = source + ": /hoses/" + std::to_string(h);
        Hose hose = [&] {
            try {
                return rig::rebuildHose(d);
            } catch (const Error& error) {
                result.errors.push_back(at + ": the hose cannot be rebuilt: " + error.what());
                throw;
            }
        }();
        if (!rig::withinStretchBand(d))
            result.warnings.push_back(at +
                                      "/restLengths: segments lie beyond their stretch band; a "
                                      "runtime keeps the exported rest lengths, so the hose "
                                      "starts overstretched or compressed");
        for (int j = 1; j + 1 < hose.pointCount(); ++j) {
            const double expected = hose.deflectionLimit(j);
            const double written = d.jointBendLimits[static_cast<size_t>(j - 1)];
            if (std::abs(expected - written) > 1e-9 * std::max(1.0, expected))
                result.errors.push_back(at + "/jointBendLimits/" + std::to_string(j - 1) +
                                        ": expected " + std::to_string(expected) +
                                        " rad (from bendLimit and the rest lengths), got " +
                                        std::to_string(written));
        }
        const std::vector<std::string> warnings = hoseWarnings(hose, at + " '" + d.id + "'");
        result.warnings.insert(result.warnings.end(), warnings.begin(), warnings.end());
    }
}

void validateProject(const fs::path& file, const formats::NamedRoots& roots,
                     ValidationResult& result)
{
    formats::ProjectLoadOptions load;
    load.roots = roots;
    const formats::Project project = formats::loadProject(file, load);
    const formats::ImportedScenes scenes = formats::importProjectScenes(project, file, roots);
    for (size_t h = 0; h < project.hoses.size(); ++h) {
        const formats::HoseDefinition& definition = project.hoses[h];
        try {
            const Hose hose = formats::buildHose(project, definition, scenes);
            const auto warnings = hoseWarnings(
                hose, file.string() + ": /hoses/" + std::to_string(h) + " '" + definition.id + "'");
            result.warnings.insert(result.warnings.end(), warnings.begin(), warnings.end());
        } catch (const Error& error) {
            result.errors.push_back(file.string() + ": /hoses/" + std::to_string(h) + ": " +
                                    error.what());
        }
    }
}

using Json = nlohmann::json;

using rig::detail::floatsOf;
using rig::detail::GltfFile;
using rig::detail::readGltf;

void validateGltf(const fs::path& file, ValidationResult& result)
{
    const std::string name = file.string();
    const GltfFile gltf = readGltf(file);
    const auto lists = [&](const char* key) {
        for (const Json& value : gltf.json.value(key, Json::array()))
            if (value == rig::kExtensionName) return true;
        return false;
    };
    if (!lists("extensionsUsed"))
        result.errors.push_back(name + ": /extensionsUsed: expected to list " +
                                rig::kExtensionName);
    if (lists("extensionsRequired"))
        result.errors.push_back(name + ": /extensionsRequired: must not list " +
                                rig::kExtensionName +
                                " (viewers that do not know it would refuse the file)");
    const Json& nodes = gltf.json.value("nodes", Json::array());
    const Json& skins = gltf.json.value("skins", Json::array());

    rig::RuntimeLoadReport loadReport;
    const rig::HoseRuntime runtime = rig::HoseRuntime::load(file, &loadReport);
    for (const std::string& w : loadReport.warnings)
        result.warnings.push_back(w);
    const rig::HoseRigDescriptor& descriptor = runtime.descriptor();
    checkDescriptorHoses(descriptor, loadReport.descriptorSource, result);

    for (size_t c = 0; c < descriptor.colliders.size(); ++c)
        if (nodes.at(static_cast<size_t>(descriptor.colliders[c])).value("mesh", -1) < 0)
            result.errors.push_back(
                loadReport.descriptorSource + ": /colliders/" + std::to_string(c) + ": node " +
                std::to_string(descriptor.colliders[c]) + " has no mesh to collide with");
    std::vector<int> isSceneRoot(nodes.size(), 0);
    for (const Json& scene : gltf.json.value("scenes", Json::array()))
        for (const Json& n : scene.value("nodes", Json::array()))
            if (n.is_number_integer() && n.get<size_t>() < nodes.size())
                isSceneRoot[n.get<size_t>()] = 1;
    for (int h = 0; h < runtime.hoseCount(); ++h) {
        const rig::RigHose& d = descriptor.hoses[static_cast<size_t>(h)];
        const std::string at = loadReport.descriptorSource + ": /hoses/" + std::to_string(h);
        if (d.isStatic) {
            // A plain mesh under its attachment node, placed so that it is where the hose is.
            const Json& meshNode = nodes.at(static_cast<size_t>(d.meshNode));
            if (meshNode.contains("skin") || meshNode.value("mesh", -1) < 0)
                result.errors.push_back(at + "/mesh: node " + std::to_string(d.meshNode) +
                                        " is not a plain (unskinned) mesh, as static says");
            const int parent = runtime.node(d.meshNode).parent;
            const int expectedParent = d.attachments.front().node;
            if (expectedParent >= 0 ? parent != expectedParent : parent < 0)
                result.errors.push_back(at + "/mesh: node " + std::to_string(d.meshNode) +
                                        " should be a child of node " +
                                        std::to_string(expectedParent) +
                                        " (the node the static hose is fixed to)");
            const Frame world = runtime.nodeWorldFrame(d.meshNode);
            if (world.translation.norm() > 1e-6 ||
                world.rotation.angularDistance(Quat::Identity()) > 1e-6)
                result.errors.push_back(at + "/mesh: the static mesh's node is not at the world "
                                             "origin at export (its vertices are world metres)");
            continue;
        }
        if (d.skin < 0) continue; // a plain mesh: nothing to pose
        const Json& meshNode = nodes.at(static_cast<size_t>(d.meshNode));
        if (meshNode.value("skin", -1) != d.skin || meshNode.value("mesh", -1) < 0)
            result.errors.push_back(at + "/mesh: node " + std::to_string(d.meshNode) +
                                    " is not a mesh skinned with skin " + std::to_string(d.skin));
        if (!isSceneRoot[static_cast<size_t>(d.meshNode)])
            result.errors.push_back(at + "/mesh: the skinned-mesh node must be a scene root");
        const Json& skin = skins.at(static_cast<size_t>(d.skin));
        if (skin.value("joints", std::vector<int>{}) != d.jointNodes)
            result.errors.push_back(at + "/joints: differ from the joints of skin " +
                                    std::to_string(d.skin) +
                                    " (expected the same nodes in axis order)");
        const std::vector<float> inverseBind =
            skin.contains("inverseBindMatrices")
                ? floatsOf(gltf, skin["inverseBindMatrices"].get<int>(),
                           name + ": /skins/" + std::to_string(d.skin))
                : std::vector<float>{};
        const std::vector<rig::JointPose>& poses = runtime.jointPoses(h);
        for (size_t i = 0; i < d.jointNodes.size() && i < poses.size(); ++i) {
            const int joint = d.jointNodes[i];
            if (nodes.at(static_cast<size_t>(joint)).contains("matrix"))
                result.errors.push_back(at + "/joints/" + std::to_string(i) + ": node " +
                                        std::to_string(joint) +
                                        " uses `matrix`; joints must be TRS");
            const Frame inFile = runtime.nodeWorldFrame(joint);
            const Frame& expected = poses[i].world;
            const double offset = (inFile.translation - expected.translation).norm();
            const double angle = inFile.rotation.angularDistance(expected.rotation);
            if (offset > 1e-4 || angle > 1e-4) {
                result.errors.push_back(at + "/joints/" + std::to_string(i) + ": joint node " +
                                        std::to_string(joint) + " is " + std::to_string(offset) +
                                        " m / " + std::to_string(angle) +
                                        " rad away from the hose's ring frame");
                break;
            }
            if (inverseBind.size() >= 16 * (i + 1)) {
                Eigen::Matrix4d ibm;
                for (int k = 0; k < 16; ++k)
                    ibm.data()[k] = inverseBind[16 * i + static_cast<size_t>(k)];
                Eigen::Matrix4d world = Eigen::Matrix4d::Identity();
                world.topLeftCorner<3, 3>() =
                    Eigen::Quaterniond(expected.rotation).toRotationMatrix();
                world.topRightCorner<3, 1>() = Eigen::Vector3d(expected.translation);
                const double bindError =
                    (world * ibm - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff();
                if (bindError > 1e-4) {
                    result.errors.push_back(at + "/joints/" + std::to_string(i) +
                                            ": the inverse bind matrix does not invert the joint's "
                                            "bind pose (error " +
                                            std::to_string(bindError) + ")");
                    break;
                }
            }
        }
    }

    fs::path sidecar = file;
    sidecar.replace_extension(".hoses.json");
    if (fs::exists(sidecar) && loadReport.descriptorSource != sidecar.string()) {
        const rig::HoseRigDescriptor beside =
            rig::parseDescriptor(rig::detail::readFileBytes(sidecar), sidecar.string());
        if (rig::serialiseDescriptor(beside) != rig::serialiseDescriptor(descriptor))
            result.errors.push_back(sidecar.string() +
                                    ": differs from the descriptor embedded in " + name);
    }
}

std::string frameText(const Frame& frame)
{
    std::ostringstream out;
    out << std::setprecision(4) << "at (" << frame.translation.x() << ", " << frame.translation.y()
        << ", " << frame.translation.z() << ") m";
    return out.str();
}

/// One hose's description; returns its warnings.
std::vector<std::string> describeHose(std::ostream& out, const std::string& id,
                                      const std::string& name, const Hose& hose,
                                      const std::array<double, 4>& colour, double roughness,
                                      const std::vector<std::string>& attachedTo)
{
    out << std::setprecision(4);
    out << "hose '" << id << "'" << (name.empty() ? "" : " (" + name + ")") << "\n"
        << "  axis: " << hose.pointCount() << " points, rest length " << hose.restLengthTotal()
        << " m, current length " << hose.currentLength() << " m\n"
        << "  material: expansion " << 100.0 * hose.material().expansionCoefficient << " %, ";
    if (hose.material().bendLimit.kind == BendLimit::Kind::MinBendRadius)
        out << "minimum bend radius " << hose.material().bendLimit.value << " m\n";
    else
        out << "deflection limit " << hose.material().bendLimit.value << " rad per joint\n";
    out << "  outer diameter " << hose.spec().outerDiameter << " m, cross-section "
        << rig::shapeName(hose.profile().shape()) << " (" << hose.profile().vertexCount() - 1
        << " vertices per ring)\n"
        << "  colour (" << colour[0] << ", " << colour[1] << ", " << colour[2] << ", " << colour[3]
        << "), roughness " << roughness << "\n";
    const Gravity& gravity = hose.spec().gravity;
    out << "  gravity: ";
    if (gravity.enabled)
        out << "on, direction (" << gravity.direction.x() << ", " << gravity.direction.y() << ", "
            << gravity.direction.z() << ")\n";
    else
        out << "off\n";
    const Torsion& torsion = hose.spec().torsion;
    out << "  torsion: ";
    if (torsion.enabled)
        out << "on, twist limit " << torsion.twistLimit << " rad ("
            << torsion.twistLimit * 180.0 / 3.14159265358979323846 << "°) per joint\n";
    else
        out << "off\n";
    if (hose.attachments().empty()) out << "  attachments: none (free hose)\n";
    for (size_t k = 0; k < hose.attachments().size(); ++k) {
        const Hose::Attachment& a = hose.attachments()[k];
        const std::string to = k < attachedTo.size() ? attachedTo[k] : std::string("the world");
        if (a.isClip())
            out << "  clip (" << toString(a.hold) << "): on " << to << ", holds the hose "
                << a.slide << " m from its start (segment " << a.first << "), end stops "
                << a.slideMin << " … " << a.slideMax << " m, " << frameText(a.frame) << "\n";
        else
            out << "  attachment " << k << ": points " << a.first << "–" << a.last << " fixed to "
                << to << ", " << frameText(a.frame) << "\n";
    }
    const std::vector<std::string> warnings = hoseWarnings(hose, "hose '" + id + "'");
    for (const std::string& warning : warnings)
        out << "  warning: " << warning << "\n";
    return warnings;
}

} // namespace

FileKind fileKindOf(const fs::path& file)
{
    const std::string extension = lower(file.extension().string());
    if (extension == formats::kProjectExtension) return FileKind::Project;
    if (extension == ".json") return FileKind::Descriptor;
    if (extension == ".glb" || extension == ".gltf") return FileKind::Gltf;
    throw InvalidArgument(file.string() + ": unknown kind of file (expected .ctproj, .hoses.json, "
                                          ".glb or .gltf)");
}

ValidationResult validateFile(const fs::path& file, const formats::NamedRoots& roots)
{
    ValidationResult result;
    try {
        result.kind = fileKindOf(file);
        switch (result.kind) {
        case FileKind::Project:
            validateProject(file, roots, result);
            break;
        case FileKind::Descriptor:
            checkDescriptorHoses(
                rig::parseDescriptor(rig::detail::readFileBytes(file), file.string()),
                file.string(), result);
            break;
        case FileKind::Gltf:
            validateGltf(file, result);
            break;
        }
    } catch (const std::exception& error) {
        const std::string what = error.what();
        // An error already recorded (and rethrown to stop) is not repeated.
        if (result.errors.empty() || result.errors.back().find(what) == std::string::npos)
            result.errors.push_back(
                what.find(file.string()) == std::string::npos ? file.string() + ": " + what : what);
    }
    return result;
}

int describeFile(const fs::path& file, const formats::NamedRoots& roots, std::ostream& out)
{
    int warnings = 0;
    switch (fileKindOf(file)) {
    case FileKind::Project: {
        formats::ProjectLoadOptions load;
        load.roots = roots;
        const formats::Project project = formats::loadProject(file, load);
        out << file.string() << ": project '" << project.name << "', " << project.scenes.size()
            << " scene(s), " << project.hoses.size() << " hose(s)\n";
        out << "colliders: " << project.colliders.size() << (project.colliders.empty() ? "\n" : "");
        for (size_t k = 0; k < project.colliders.size(); ++k)
            out << (k == 0 ? " — " : ", ") << "scene '" << project.colliders[k].scene << "' node "
                << project.colliders[k].node << (k + 1 == project.colliders.size() ? "\n" : "");
        out << "sockets: " << project.sockets.size() << (project.sockets.empty() ? "\n" : "");
        for (size_t k = 0; k < project.sockets.size(); ++k) {
            const formats::Socket& socket = project.sockets[k];
            out << (k == 0 ? " — " : ", ") << socket.id << " (tag '" << socket.tag << "', scene '"
                << socket.scene << "' node " << socket.node << ")"
                << (k + 1 == project.sockets.size() ? "\n" : "");
        }
        const formats::ImportedScenes scenes = formats::importProjectScenes(project, file, roots);
        for (const formats::HoseDefinition& definition : project.hoses) {
            std::vector<std::string> attachedTo;
            for (const formats::HoseAttachment& a : definition.attachments)
                attachedTo.push_back("scene '" + a.scene + "' node " + a.node);
            for (const formats::HoseClip& c : definition.clips)
                attachedTo.push_back("scene '" + c.scene + "' node " + c.node);
            const Hose hose = formats::buildHose(project, definition, scenes);
            warnings += static_cast<int>(describeHose(out, definition.id, definition.name, hose,
                                                      {definition.colour.r, definition.colour.g,
                                                       definition.colour.b, definition.colour.a},
                                                      definition.roughness, attachedTo)
                                             .size());
            if (!definition.plugs.empty())
                out << "  plugs: start "
                    << (definition.plugs.start.empty() ? "—" : "'" + definition.plugs.start + "'")
                    << ", end "
                    << (definition.plugs.end.empty() ? "—" : "'" + definition.plugs.end + "'")
                    << "\n";
        }
        break;
    }
    case FileKind::Descriptor:
    case FileKind::Gltf: {
        const bool gltf = fileKindOf(file) == FileKind::Gltf;
        std::optional<rig::HoseRuntime> runtime;
        rig::HoseRigDescriptor descriptor;
        if (gltf) {
            runtime.emplace(rig::HoseRuntime::load(file));
            descriptor = runtime->descriptor();
        } else {
            descriptor = rig::parseDescriptor(rig::detail::readFileBytes(file), file.string());
        }
        out << file.string() << ": hose rig " << descriptor.version << " ("
            << (descriptor.generator.empty() ? "unknown generator" : descriptor.generator) << "), "
            << descriptor.hoses.size() << " hose(s)\n";
        out << "colliders: " << descriptor.colliders.size()
            << (descriptor.colliders.empty() ? "\n" : "");
        for (size_t k = 0; k < descriptor.colliders.size(); ++k) {
            const int node = descriptor.colliders[k];
            out << (k == 0 ? " — " : ", ") << "node " << node;
            if (runtime && node >= 0 && node < runtime->nodeCount())
                out << " '" << runtime->node(node).name << "'";
            out << (k + 1 == descriptor.colliders.size() ? "\n" : "");
        }
        out << "motions: " << descriptor.motions.size() << (descriptor.motions.empty() ? "\n" : "");
        for (size_t k = 0; k < descriptor.motions.size(); ++k) {
            const rig::RigMotion& motion = descriptor.motions[k];
            const bool hinge = motion.kind == rig::RigMotion::Kind::Hinge;
            out << (k == 0 ? " — " : ", ") << motion.id << " (" << rig::motionKindName(motion.kind)
                << " of node " << motion.node;
            if (runtime && motion.node >= 0 && motion.node < runtime->nodeCount())
                out << " '" << runtime->node(motion.node).name << "'";
            out << ", " << motion.minimum << " … " << motion.maximum << (hinge ? " rad)" : " m)")
                << (k + 1 == descriptor.motions.size() ? "\n" : "");
        }
        out << "sockets: " << descriptor.sockets.size() << (descriptor.sockets.empty() ? "\n" : "");
        for (size_t k = 0; k < descriptor.sockets.size(); ++k) {
            const rig::RigSocket& socket = descriptor.sockets[k];
            out << (k == 0 ? " — " : ", ") << socket.id << " (tag '" << socket.tag << "', "
                << (socket.node < 0 ? "the world" : "node " + std::to_string(socket.node));
            if (runtime && socket.node >= 0 && socket.node < runtime->nodeCount())
                out << " '" << runtime->node(socket.node).name << "'";
            out << ")" << (k + 1 == descriptor.sockets.size() ? "\n" : "");
        }
        for (const rig::RigHose& d : descriptor.hoses) {
            std::vector<std::string> attachedTo;
            for (const rig::RigAttachment& a : d.attachments) {
                std::string label = a.node < 0 ? "the world" : "node " + std::to_string(a.node);
                if (runtime && a.node >= 0) label += " '" + runtime->node(a.node).name + "'";
                attachedTo.push_back(label);
            }
            for (const rig::RigClip& c : d.clips) {
                std::string label = c.node < 0 ? "the world" : "node " + std::to_string(c.node);
                if (runtime && c.node >= 0) label += " '" + runtime->node(c.node).name + "'";
                attachedTo.push_back(label);
            }
            warnings += static_cast<int>(describeHose(out, d.id, d.name, rig::rebuildHose(d),
                                                      d.baseColour, d.roughness, attachedTo)
                                             .size());
            if (!d.plugStart.empty() || !d.plugEnd.empty())
                out << "  plugs: start " << (d.plugStart.empty() ? "—" : "'" + d.plugStart + "'")
                    << ", end " << (d.plugEnd.empty() ? "—" : "'" + d.plugEnd + "'") << "\n";
            if (d.skin >= 0)
                out << "  rig: skinned mesh node " << d.meshNode << ", skin " << d.skin << ", "
                    << d.jointNodes.size() << " joints, " << d.grabbablePoints.size()
                    << " grabbable points\n";
        }
        break;
    }
    }
    return warnings;
}

} // namespace chaintube::exporting
