#include "gltf_model.h"

#include "chaintube/formats/errors.h"

#include <cmath>

namespace chaintube::exporting::detail {

namespace fs = std::filesystem;

namespace {

std::vector<double> toVector(const Vec3& v)
{
    return {v.x(), v.y(), v.z()};
}

} // namespace

Affine affineOf(const formats::Mat4& m)
{
    return Affine(m);
}

void setTransform(tinygltf::Node& node, const Affine& local, bool allowMatrix,
                  const std::string& what)
{
    rig::NodeTransform trs;
    if (!rig::detail::decompose(local, trs)) {
        if (!allowMatrix)
            throw InvalidArgument(what + ": its parent's world transform has shear, so the joint "
                                         "cannot be expressed as a glTF TRS node");
        node.matrix.assign(local.data(), local.data() + 16); // column-major, as glTF
        return;
    }
    if (trs.translation.norm() > 0) node.translation = toVector(trs.translation);
    if (!trs.rotation.coeffs().isApprox(Quat::Identity().coeffs(), 0.0))
        node.rotation = {trs.rotation.x(), trs.rotation.y(), trs.rotation.z(), trs.rotation.w()};
    if ((trs.scale - Vec3::Ones()).cwiseAbs().maxCoeff() > 1e-12) node.scale = toVector(trs.scale);
}

std::vector<float> unitNormals(const std::vector<float>& normals)
{
    std::vector<float> result(normals.size());
    for (size_t v = 0; v + 2 < normals.size(); v += 3) {
        const Eigen::Vector3d n(normals[v], normals[v + 1], normals[v + 2]);
        const double length = n.norm();
        const Eigen::Vector3d unit = (std::isfinite(length) && length > 1e-12)
                                         ? Eigen::Vector3d(n / length)
                                         : Eigen::Vector3d::UnitY();
        for (int c = 0; c < 3; ++c)
            result[v + static_cast<size_t>(c)] = static_cast<float>(unit(c));
    }
    return result;
}

SceneMeshAccessors writeSceneMesh(BufferWriter& buffer, const formats::SceneMesh& mesh)
{
    SceneMeshAccessors result;
    std::vector<std::uint32_t> triangles;
    triangles.reserve(mesh.indices.size());
    const size_t vertices = mesh.vertexCount();
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        if (a == b || b == c || a == c || a >= vertices || b >= vertices || c >= vertices)
            continue; // degenerate or broken triangles carry no surface
        triangles.insert(triangles.end(), {a, b, c});
    }
    if (triangles.empty() || vertices == 0) return result;
    result.empty = false;
    result.position = buffer.vec3Floats(mesh.positions, true);
    if (mesh.normals.size() == mesh.positions.size())
        result.normal = buffer.vec3Floats(unitNormals(mesh.normals), false);
    result.indices = buffer.indices(triangles, vertices);
    return result;
}

void reportProgress(const ExportOptions& options, double fraction, const fs::path& output)
{
    if (options.progress && !options.progress(fraction)) throw formats::Cancelled(output);
}

} // namespace chaintube::exporting::detail
