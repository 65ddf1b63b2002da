// ctscene-dump: prints an imported scene's node tree (paths, meshes, triangle counts) and the
// detected units. For authors writing attachments by hand and for checking an importer.
//
//   ctscene-dump <scene file> [metres-per-unit]
#include "chaintube/formats/scene_import.h"

#include <cstdio>
#include <cstdlib>
#include <exception>

int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s <scene file> [metres-per-unit]\n", argv[0]);
        return 2;
    }
    try {
        chaintube::formats::ImportOptions options;
        if (argc > 2) options.metresPerUnit = std::atof(argv[2]);
        const auto scene = chaintube::formats::importScene(argv[1], options);
        const auto& units = scene.sourceUnits;
        std::printf("format %s, unit %s (%g m, %s), up %s (%s), %zu nodes, %zu meshes, "
                    "%zu triangles instanced\n",
                    scene.format.c_str(), units.unitName.c_str(), units.metresPerUnit,
                    toString(units.unitSource), toString(units.upAxis),
                    toString(units.upAxisSource), scene.nodes.size(), scene.meshes.size(),
                    scene.instancedTriangleCount());
        for (size_t i = 0; i < scene.nodes.size(); ++i) {
            const auto& node = scene.nodes[i];
            const auto world = scene.worldTransform(static_cast<int>(i));
            size_t triangles = 0;
            for (int mesh : node.meshes)
                triangles += scene.meshes[size_t(mesh)].triangleCount();
            std::printf("%s%s  meshes=%zu tris=%zu world=(%.4f %.4f %.4f)\n", node.path.c_str(),
                        node.generatedName ? " [generated]" : "", node.meshes.size(), triangles,
                        world(0, 3), world(1, 3), world(2, 3));
        }
    } catch (const std::exception& error) {
        std::fprintf(stderr, "%s\n", error.what());
        return 1;
    }
    return 0;
}
