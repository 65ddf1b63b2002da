// Helpers for formats tests: small generated scene files (and the shared test support).
#pragma once

#include "chaintube/test_support/files.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <string>

namespace chaintube::formats::testing {

namespace fs = std::filesystem;

using test_support::readText;
using test_support::TemporaryFolder;
using test_support::writeText;

/// A binary STL with `triangles` triangles tiling a strip in the XY plane (unit: 1 per cell).
inline void writeBinaryStl(const fs::path& file, std::uint32_t triangles)
{
    std::ofstream stream(file, std::ios::binary);
    char header[80] = "chaintube test strip";
    stream.write(header, 80);
    stream.write(reinterpret_cast<const char*>(&triangles), 4);
    std::vector<char> record(50, 0);
    for (std::uint32_t t = 0; t < triangles; ++t) {
        const float x = static_cast<float>(t / 2), up = (t % 2) ? 1.0f : 0.0f;
        const float data[12] = {0, 0, 1, x, 0, 0, x + 1, up, 0, x, 1, 0};
        std::memcpy(record.data(), data, sizeof data);
        stream.write(record.data(), 50);
    }
}

/// A COLLADA file in millimetres with +Z up: frame (at x = 100 mm) → bracket (y = +50 mm),
/// bracket (y = −50 mm, same name), an unnamed node (z = +20 mm); each child instances a
/// 4-triangle tetrahedron of 10 mm.
inline std::string colladaRig()
{
    return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="tetra-mesh" name="tetra">
      <mesh>
        <source id="tetra-positions">
          <float_array id="tetra-positions-array" count="12">0 0 0 10 0 0 0 10 0 0 0 10</float_array>
          <technique_common><accessor source="#tetra-positions-array" count="4" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
          </accessor></technique_common>
        </source>
        <vertices id="tetra-vertices"><input semantic="POSITION" source="#tetra-positions"/></vertices>
        <triangles count="4"><input semantic="VERTEX" source="#tetra-vertices" offset="0"/>
          <p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="frame" name="frame">
        <translate>100 0 0</translate>
        <node id="bracket" name="bracket"><translate>0 50 0</translate><instance_geometry url="#tetra-mesh"/></node>
        <node id="bracket_b" name="bracket"><translate>0 -50 0</translate><instance_geometry url="#tetra-mesh"/></node>
        <node><translate>0 0 20</translate><instance_geometry url="#tetra-mesh"/></node>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
)";
}

} // namespace chaintube::formats::testing
