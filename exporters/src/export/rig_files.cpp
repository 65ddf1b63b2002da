// Writing an export's files: the model serialised by tinygltf with the descriptor set as plain
// JSON, the GLB container (or .gltf + .bin) and the sidecar descriptor, staged and renamed so
// that a failure leaves a previous export as it was.
#include "chaintube/formats/atomic_file.h"
#include "chaintube/formats/errors.h"
#include "gltf_model.h"

#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>
#include <utility>

namespace chaintube::exporting::detail {

namespace fs = std::filesystem;

namespace {

/// The GLB container around a JSON text and a binary chunk.
std::string glbBytes(std::string json, const std::vector<unsigned char>& bin)
{
    while (json.size() % 4)
        json.push_back(' ');
    std::string binary(bin.begin(), bin.end());
    while (binary.size() % 4)
        binary.push_back('\0');
    const auto u32 = [](std::uint32_t value) {
        std::string bytes(4, '\0');
        std::memcpy(bytes.data(), &value, 4);
        return bytes;
    };
    const size_t total = 12 + 8 + json.size() + (binary.empty() ? 0 : 8 + binary.size());
    std::string out = "glTF" + u32(2) + u32(static_cast<std::uint32_t>(total));
    out += u32(static_cast<std::uint32_t>(json.size())) + u32(0x4E4F534Au) + json;
    if (!binary.empty())
        out += u32(static_cast<std::uint32_t>(binary.size())) + u32(0x004E4942u) + binary;
    return out;
}

} // namespace

void writeRigFiles(tinygltf::Model& model, const rig::HoseRigDescriptor& descriptor,
                   Container container, const fs::path& output, const ExportOptions& options,
                   ExportReport& report)
{
    // tinygltf serialises the model; the descriptor is then set as plain JSON, so that empty
    // lists stay [] (tinygltf::Value writes an empty array as null) and numbers keep full
    // double precision.
    std::ostringstream stream;
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, stream, false, container == Container::Glb))
        throw formats::FileError(output, "tinygltf could not serialise the model");
    std::string written = stream.str();
    std::string jsonText = written;
    if (container == Container::Glb) {
        std::uint32_t jsonLength = 0;
        std::memcpy(&jsonLength, written.data() + 12, 4);
        jsonText = written.substr(20, jsonLength);
    }
    nlohmann::ordered_json gltf = nlohmann::ordered_json::parse(jsonText);
    const std::string descriptorText = rig::serialiseDescriptor(descriptor);
    gltf["extensions"][rig::kExtensionName] = nlohmann::ordered_json::parse(descriptorText);
    fs::path binFile;
    if (container == Container::Gltf && !model.buffers.empty()) {
        binFile = output;
        binFile.replace_extension(".bin");
        gltf["buffers"][0]["uri"] = binFile.filename().string();
    }
    reportProgress(options, 0.9, output);

    fs::path descriptorFile = output;
    descriptorFile.replace_extension(".hoses.json");
    std::vector<std::pair<fs::path, std::string>> files;
    if (!binFile.empty())
        files.emplace_back(binFile,
                           std::string(model.buffers[0].data.begin(), model.buffers[0].data.end()));
    if (options.writeSidecarDescriptor) files.emplace_back(descriptorFile, descriptorText);
    files.emplace_back(output, container == Container::Glb
                                   ? glbBytes(gltf.dump(), model.buffers.empty()
                                                               ? std::vector<unsigned char>{}
                                                               : model.buffers[0].data)
                                   : gltf.dump(1) + "\n");
    // Every file is first written completely beside its target (<file>.partial); only when all
    // are on disk are they renamed over the targets, so a full disk or a write error leaves a
    // previous export's .glb/.gltf, .bin and .hoses.json all as they were (not a new sidecar
    // beside an old glTF). The glTF itself is renamed last: it is what readers open.
    struct Staged
    {
        fs::path partial;
        fs::path target;
        bool targetExisted = false;
    };
    std::vector<Staged> staged;
    try {
        for (const auto& [file, contents] : files) {
            std::error_code error;
            if (fs::is_directory(file, error))
                throw formats::FileError(file, "cannot replace the file: it is a folder");
            fs::path partial = file;
            partial += ".partial";
            const bool existed = fs::exists(file, error);
            formats::writeFileAtomically(partial, contents);
            staged.push_back({partial, file, existed});
            report.bytesWritten += contents.size();
        }
    } catch (...) {
        std::error_code ignored;
        for (const Staged& s : staged)
            fs::remove(s.partial, ignored);
        throw;
    }
    // Renames within one folder fail only in exotic cases (the folder's permissions changed
    // meanwhile): then the files this call created are removed again and the staged ones
    // deleted; a target already replaced cannot be given back.
    for (size_t i = 0; i < staged.size(); ++i) {
        std::error_code error;
        fs::rename(staged[i].partial, staged[i].target, error);
        if (!error) continue;
        std::error_code ignored;
        for (size_t j = 0; j < staged.size(); ++j) {
            if (j < i && !staged[j].targetExisted) fs::remove(staged[j].target, ignored);
            if (j >= i) fs::remove(staged[j].partial, ignored);
        }
        throw formats::FileError(staged[i].target, "cannot replace the file: " + error.message());
    }
    report.gltfFile = output;
    report.binFile = binFile;
    if (options.writeSidecarDescriptor) report.descriptorFile = descriptorFile;
}

} // namespace chaintube::exporting::detail
