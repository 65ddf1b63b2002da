// The scene the test reader program (test_reader_main.cpp) hands over for "scene", and the
// test (reader_process_test.cpp) compares with.
#pragma once

#include "import_internal.h"

namespace chaintube::formats::detail {

inline ReaderResult testReaderScene()
{
    ReaderResult sent;
    sent.metresPerReaderUnit = 0.001;
    sent.sourceUnitsPerReaderUnit = 2.0;
    sent.scene.format = "PLY";
    sent.scene.sourceUnits = {0.001, "millimetre", UnitSource::FileHeader, UpAxis::PositiveZ,
                              UnitSource::FormatConvention};
    SceneMesh mesh;
    mesh.name = "tri";
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    mesh.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    mesh.indices = {0, 1, 2};
    sent.scene.meshes = {mesh};
    SceneNode root, child;
    root.name = "root";
    root.children = {1};
    child.name = "part";
    child.parent = 0;
    child.meshes = {0};
    child.localTransform(0, 3) = 0.25;
    sent.scene.nodes = {root, child};
    return sent;
}

} // namespace chaintube::formats::detail
