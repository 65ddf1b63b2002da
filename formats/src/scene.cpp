#include "chaintube/formats/scene.h"

namespace chaintube::formats {

const char* toString(UnitSource source)
{
    switch (source) {
    case UnitSource::FileHeader:
        return "stated in the file";
    case UnitSource::FormatConvention:
        return "fixed by the format";
    case UnitSource::Assumed:
        return "assumed (the format does not say)";
    case UnitSource::UserOverride:
        return "set by the user";
    }
    return "?";
}

const char* toString(UpAxis axis)
{
    return axis == UpAxis::PositiveY ? "+Y" : "+Z";
}

int ImportedScene::findNode(std::string_view nodePath) const
{
    for (size_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].path == nodePath) return static_cast<int>(i);
    return -1;
}

std::vector<int> ImportedScene::findNodesByName(std::string_view name) const
{
    std::vector<int> found;
    for (size_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].name == name) found.push_back(static_cast<int>(i));
    return found;
}

Mat4 ImportedScene::worldTransform(int node) const
{
    Mat4 world = Mat4::Identity();
    for (int i = node; i >= 0; i = nodes.at(static_cast<size_t>(i)).parent)
        world = nodes[static_cast<size_t>(i)].localTransform * world;
    return world;
}

Frame ImportedScene::worldFrame(int node) const
{
    return rigidPart(worldTransform(node));
}

std::size_t ImportedScene::instancedTriangleCount() const
{
    std::size_t count = 0;
    for (const SceneNode& node : nodes)
        for (int mesh : node.meshes)
            count += meshes[static_cast<size_t>(mesh)].triangleCount();
    return count;
}

std::size_t ImportedScene::meshTriangleCount() const
{
    std::size_t count = 0;
    for (const SceneMesh& mesh : meshes)
        count += mesh.triangleCount();
    return count;
}

} // namespace chaintube::formats
