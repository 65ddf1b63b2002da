// Shared helpers of the editor tests.
#pragma once

#include "chaintube/editor/commands.h"
#include "chaintube/editor/document.h"
#include "chaintube/test_support/files.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

namespace chaintube::editor::test {

using test_support::haveScenes;
using test_support::samplesDir;
using test_support::scenesDir;
inline formats::NamedRoots roots()
{
    return {{"scenes", scenesDir()}};
}
/// Folder for files the tests write (created; inside the build tree).
inline std::filesystem::path outputDir()
{
    const std::filesystem::path dir = CHAINTUBE_TEST_OUTPUT_DIR;
    std::filesystem::create_directories(dir);
    return dir;
}

/// Adds to a document holding the test rig a 0.25 m rubber hose sticking out of the left
/// bracket horizontally along −X, its first two axis points fixed to the bracket and the rest
/// free (undo steps "Add hose" and the fix). Under gravity it hangs down and settles, unlike
/// the rig's own bend-limited hoses held at both ends. Returns its id.
inline std::string addCantilever(Document& document)
{
    formats::HoseDefinition cantilever;
    cantilever.id = "cantilever";
    cantilever.name = "cantilever from the left bracket";
    cantilever.route = {Vec3(-0.3, 0.21, -0.06), Vec3(-0.55, 0.21, -0.06)};
    cantilever.material = formats::PresetName{"rubber hose"};
    cantilever.outerDiameter = 0.016;
    cantilever.segmentCount = 16;
    cantilever.colour = {0.1, 0.3, 0.75, 1.0};
    document.undoStack()->push(new AddHoseCommand(document, cantilever));
    const int bracket = document.scene("rig")->findNode("/test-rig/bracket_left");
    document.undoStack()->push(makeAttach(document, cantilever.id, 0, 1, "rig", bracket));
    return cantilever.id;
}

/// The lowest y a hose fixed by its first segment (points 0 and 1) can reach under gravity
/// along −Y: every free segment at its longest (maxLength) and turned from the one before it
/// towards straight down by the largest deflection its joint allows. Each point is then as
/// low as the constraints let it be, so this is the exact equilibrium of the model (world
/// metres); the last point is the lowest.
inline double lowestReachableY(const Hose& hose)
{
    const Vec3 first = (hose.point(1) - hose.point(0)).normalized();
    double fromDown = std::acos(std::clamp(first.dot(Vec3(0.0, -1.0, 0.0)), -1.0, 1.0));
    double y = hose.point(1).y();
    for (int segment = 1; segment < hose.segmentCount(); ++segment) {
        fromDown = std::max(0.0, fromDown - hose.deflectionLimit(segment));
        y -= hose.maxLength(segment) * std::cos(fromDown);
    }
    return y;
}

inline double lowestY(const std::vector<Vec3>& points)
{
    double lowest = points.front().y();
    for (const Vec3& point : points)
        lowest = std::min(lowest, point.y());
    return lowest;
}

} // namespace chaintube::editor::test
