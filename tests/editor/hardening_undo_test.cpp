// Hardening ("nothing lost"): 10,000 random edits of a document through its undo
// commands, then undoing all of them restores the original project exactly and redoing all of
// them restores the final one (compared through Document::stateFingerprint, i.e.
// serialiseProject plus pose overrides and scene ids, at every step of the way), and the live
// hoses follow. Runs under QT_QPA_PLATFORM=offscreen.
#include "chaintube/editor/commands.h"
#include "chaintube/editor/document.h"
#include "test_support.h"

#include <cstdlib>
#include <functional>
#include <gtest/gtest.h>
#include <memory>
#include <random>

namespace chaintube::editor {
namespace {

using test::roots;
using test::samplesDir;

std::vector<std::vector<Vec3>> livePoints(const Document& document)
{
    std::vector<std::vector<Vec3>> points;
    for (const auto& hose : document.project().hoses)
        points.push_back(document.hose(hose.id) ? document.hose(hose.id)->points()
                                                : std::vector<Vec3>{});
    return points;
}

/// Makes one random edit of `document` and pushes it; returns false if the edit it drew was
/// refused (an overlapping attachment, a drag of a hose fixed to a moved part, …).
class RandomEditor
{
public:
    RandomEditor(Document& document, std::uint32_t seed) : m_document(document), m_random(seed)
    {
        const formats::ImportedScene* rig = document.scene("rig");
        for (int node = 0; rig && node < static_cast<int>(rig->nodes.size()); ++node)
            m_nodes.push_back(node);
    }

    bool editOnce()
    {
        Document& d = m_document;
        // Mostly separate steps; sometimes a run of merging edits like a slider drag.
        if (uniform(0, 1) < 0.85) d.closeMerge();
        const auto& hoses = d.project().hoses;
        const std::string id = hoses[index(hoses.size())].id;
        const formats::HoseDefinition& hose = *d.hoseDefinition(id);
        using formats::HoseDefinition;
        switch (index(12)) {
        case 0:
            return push(makeChangeHoseField(d, id, &HoseDefinition::outerDiameter,
                                            uniform(0.006, 0.04), MergeId::HoseDiameter, "d"));
        case 1:
            return push(makeChangeHoseField(d, id, &HoseDefinition::segmentCount,
                                            static_cast<int>(4 + index(30)), MergeId::HoseSegments,
                                            "n"));
        case 2:
            return push(makeChangeHoseField(d, id, &HoseDefinition::name,
                                            "hose " + std::to_string(index(1000)),
                                            MergeId::HoseName, "name"));
        case 3: {
            formats::Rgba colour{uniform(0, 1), uniform(0, 1), uniform(0, 1), 1.0};
            return push(makeChangeHoseField(d, id, &HoseDefinition::colour, colour,
                                            MergeId::HoseColour, "colour"));
        }
        case 4: { // move a route point a little
            std::vector<Vec3> route = hose.route;
            route[index(route.size())] += randomVector(0.01);
            return push(makeSetRoute(d, id, route, "move", MergeId::HoseRoute));
        }
        case 5: { // insert or delete a route point
            std::vector<Vec3> route = hose.route;
            if (route.size() > 3 && uniform(0, 1) < 0.5) {
                route.erase(route.begin() + static_cast<long>(1 + index(route.size() - 2)));
            } else {
                const size_t at = 1 + index(route.size() - 1);
                route.insert(route.begin() + static_cast<long>(at),
                             0.5 * (route[at - 1] + route[at]) + randomVector(0.01));
            }
            return push(makeSetRoute(d, id, route, "route"));
        }
        case 6: { // add a hose, or remove one (keeping at least one)
            if (hoses.size() > 1 && uniform(0, 1) < 0.5) return push(new RemoveHoseCommand(d, id));
            formats::HoseDefinition added;
            added.id = d.unusedHoseId();
            added.name = "added";
            const Vec3 start = randomVector(0.3);
            added.route = {start, start + Vec3(0.2, 0.05, 0.0) + randomVector(0.02),
                           start + Vec3(0.3, 0.0, 0.2) + randomVector(0.02)};
            return push(new AddHoseCommand(d, added));
        }
        case 7: { // fix a range to a scene node, or free one
            if (!hose.attachments.empty() && uniform(0, 1) < 0.5)
                return push(makeDetach(d, id, static_cast<int>(index(hose.attachments.size()))));
            if (m_nodes.empty() || !d.hose(id)) return false;
            const int points = d.hose(id)->pointCount();
            const int first = static_cast<int>(index(static_cast<size_t>(points)));
            const int last = std::min(points - 1, first + static_cast<int>(index(2)));
            try {
                return push(makeAttach(d, id, first, last, "rig", m_nodes[index(m_nodes.size())]));
            } catch (const InvalidArgument&) {
                return false; // overlaps an attachment: refused, nothing pushed
            }
        }
        case 8: { // move a part (hoses fixed to it follow), or put it back to the file pose
            if (m_nodes.empty()) return false;
            const NodeKey node{"rig", m_nodes[index(m_nodes.size())]};
            if (uniform(0, 1) < 0.3) return push(makeSetNodeTransform(d, node, std::nullopt));
            formats::Mat4 moved = d.nodeLocalTransform(node.first, node.second);
            moved.block<3, 1>(0, 3) += randomVector(0.02);
            return push(makeSetNodeTransform(d, node, moved));
        }
        case 9: { // save an own preset, or drop the last one
            auto presets = d.project().materialPresets;
            if (presets.size() > 3 && uniform(0, 1) < 0.5) {
                presets.pop_back();
            } else {
                formats::MaterialPreset own;
                own.name = "own " + std::to_string(m_presetCounter++);
                own.material.expansionCoefficient = uniform(0.0, 0.2);
                own.material.bendLimit = BendLimit::minBendRadius(uniform(0.02, 0.2));
                presets.push_back(own);
            }
            return push(makeSetPresets(d, presets, "presets"));
        }
        case 10: {
            formats::ExportSettings settings = d.project().exportSettings;
            settings.format = uniform(0, 1) < 0.5 ? "glb" : "gltf";
            settings.path = "out-" + std::to_string(index(100)) + "." + settings.format;
            settings.includeScene = uniform(0, 1) < 0.5;
            return push(makeSetExportSettings(d, settings));
        }
        default: { // grab-drag a free point and commit it as the route
            const Hose* live = d.hose(id);
            if (!live) return false;
            const int point = static_cast<int>(index(static_cast<size_t>(live->pointCount())));
            if (live->isFixed(point)) return false;
            const Vec3 start = live->point(point);
            for (int step = 1; step <= 3; ++step)
                if (d.dragHosePoint(id, point, start + step * randomVector(0.01)).status ==
                    Status::InvalidInput) {
                    d.cancelHoseDrag(id);
                    return false;
                }
            if (d.commitHoseDrag(id)) return true;
            return false; // fixed to a moved part: refused, the shape was restored
        }
        }
    }

private:
    bool push(QUndoCommand* command)
    {
        m_document.undoStack()->push(command);
        return true;
    }
    double uniform(double low, double high)
    {
        return std::uniform_real_distribution<double>(low, high)(m_random);
    }
    size_t index(size_t count)
    {
        return std::uniform_int_distribution<size_t>(0, count - 1)(m_random);
    }
    Vec3 randomVector(double size)
    {
        return Vec3(uniform(-size, size), uniform(-size, size), uniform(-size, size));
    }

    Document& m_document;
    std::mt19937 m_random;
    std::vector<int> m_nodes;
    int m_presetCounter = 0;
};

TEST(HardeningUndo, TenThousandRandomEditsUndoToTheOriginalAndRedoToTheFinalProject)
{
    const char* seedText = std::getenv("CHAINTUBE_UNDO_SEED");
    const std::uint32_t seed =
        seedText ? static_cast<std::uint32_t>(std::strtoul(seedText, nullptr, 10)) : 20261122u;
    SCOPED_TRACE("seed " + std::to_string(seed) + " (set CHAINTUBE_UNDO_SEED to replay another)");
    Document document(roots());
    document.adopt(readProject(samplesDir() / "test-rig.ctproj", roots()));
    QUndoStack& stack = *document.undoStack();
    ASSERT_EQ(stack.count(), 0);

    // The state after every undo step, by stack index (a merged edit overwrites its step's).
    std::vector<std::string> states{document.stateFingerprint()};
    const auto originalPoints = livePoints(document);
    RandomEditor editor(document, seed);
    constexpr int edits = 10000;
    int made = 0, refused = 0;
    while (made < edits) {
        if (!editor.editOnce()) {
            ++refused;
            ASSERT_EQ(states[static_cast<size_t>(stack.index())], document.stateFingerprint())
                << "a refused edit changed the document";
            continue;
        }
        ++made;
        states.resize(static_cast<size_t>(stack.index()) + 1);
        states.back() = document.stateFingerprint();
    }
    const std::string finalState = document.stateFingerprint();
    const auto finalPoints = livePoints(document);
    ASSERT_NE(states.front(), finalState);
    RecordProperty("edits", made);
    RecordProperty("refused", refused);
    RecordProperty("undoSteps", stack.count());
    std::printf("%d edits (%d drawn edits refused), %d undo steps after merging\n", made, refused,
                stack.count());
    ASSERT_GT(stack.count(), edits / 2) << "most edits must be separate undo steps";

    while (stack.canUndo()) {
        stack.undo();
        ASSERT_EQ(states[static_cast<size_t>(stack.index())], document.stateFingerprint())
            << "after undoing down to step " << stack.index();
    }
    EXPECT_EQ(states.front(), document.stateFingerprint());
    EXPECT_EQ(originalPoints, livePoints(document)) << "live hoses not back at the original shape";

    while (stack.canRedo()) {
        stack.redo();
        ASSERT_EQ(states[static_cast<size_t>(stack.index())], document.stateFingerprint())
            << "after redoing up to step " << stack.index();
    }
    EXPECT_EQ(finalState, document.stateFingerprint());
    EXPECT_EQ(finalPoints, livePoints(document)) << "live hoses not back at the final shape";
}

} // namespace
} // namespace chaintube::editor
