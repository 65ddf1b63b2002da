// The attached parts of the self-contained samples (test rig, motion rig, single hose) walked
// the way a part is dragged in the editor or moved in a VR scene: along X, Y and Z in 2 mm
// steps and turned about X, Y and Z in 2° steps, out and back, through the library's
// attachment moves alone. After every update no segment is outside its stretch band, and on a
// hose without clips (whose reach does not depend on a slide) every attachment within 99 % of
// the reach of the segments to its neighbouring attachments is met (to 1e-6 m). Back one step from
// where it started and held there (at most 32 updates), each hose whose direct move there has no
// problem comes to one without any (measure(); through a clip the bend radius taken from compressed
// segments excepted): a kink forced while the part was far straightens once the part comes back.
#include "chaintube/formats/project_hoses.h"

#include <chaintube/chaintube.h>
#include <cmath>
#include <gtest/gtest.h>
#include <numbers>
#include <string>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;

/// A hose's attachments (and clips) that move with one part: their ids and frames at the file
/// pose.
struct Carried
{
    int id = 0;
    Frame frame;
};

/// One sample loaded: its hoses and, per part (a scene node some attachment names, with the
/// nodes below it), what each hose has attached to it.
struct Sample
{
    std::vector<Hose> hoses;
    std::vector<HoseDefinition> definitions;
    /// part path → per hose, the carried attachments
    std::vector<std::pair<std::string, std::vector<std::vector<Carried>>>> parts;
    std::vector<Vec3> partOrigins; ///< each part's world position (the turns' centre)
};

Sample loadSample(const char* name)
{
    const fs::path file = kSamples / name;
    const Project project = loadProject(file);
    const ImportedScenes scenes = importProjectScenes(project, file, {});
    Sample s;
    s.hoses = buildHoses(project, scenes);
    s.definitions = project.hoses;
    std::vector<std::pair<std::string, std::string>> nodes; // (scene, node) of every attachment
    for (const HoseDefinition& d : project.hoses) {
        for (const HoseAttachment& a : d.attachments)
            nodes.emplace_back(a.scene, a.node);
        for (const HoseClip& c : d.clips)
            nodes.emplace_back(c.scene, c.node);
    }
    // A part is a node no other attachment's node lies above.
    for (const auto& [scene, node] : nodes) {
        bool below = false;
        for (const auto& other : nodes)
            below = below || (other.second != node && node.rfind(other.second + "/", 0) == 0);
        bool known = false;
        for (const auto& part : s.parts)
            known = known || part.first == node;
        if (below || known) continue;
        std::vector<std::vector<Carried>> carried(s.hoses.size());
        for (size_t h = 0; h < s.hoses.size(); ++h) {
            const HoseDefinition& d = project.hoses[h];
            const std::vector<Hose::Attachment>& built = s.hoses[h].attachments();
            // buildHoses attaches the attachments in order, then the clips.
            size_t k = 0;
            auto take = [&](const std::string& at) {
                if (at == node || at.rfind(node + "/", 0) == 0)
                    carried[h].push_back({built[k].id, built[k].frame});
                ++k;
            };
            for (const HoseAttachment& a : d.attachments)
                take(a.node);
            for (const HoseClip& c : d.clips)
                take(c.node);
        }
        const ImportedScene& imported = scenes.at(scene);
        s.partOrigins.push_back(imported.worldFrame(imported.findNode(node)).translation);
        s.parts.emplace_back(node, std::move(carried));
    }
    return s;
}

/// The rigid motion of a walk at `amount` (metres along `axis`, or radians about it through
/// `centre` when `turn`).
Frame motion(const Vec3& axis, bool turn, double amount, const Vec3& centre)
{
    Frame m;
    if (turn) {
        m.rotation = Quat(Eigen::AngleAxisd(amount, axis));
        m.translation = centre - m.rotation * centre;
    } else {
        m.translation = amount * axis;
    }
    return m;
}

/// Moves every carried attachment of hose `h` to `m` applied to its file-pose frame.
UpdateResult moveTo(Hose& hose, const std::vector<Carried>& carried, const Frame& m)
{
    std::vector<int> ids;
    std::vector<Frame> frames;
    for (const Carried& c : carried) {
        ids.push_back(c.id);
        frames.push_back(m * c.frame);
    }
    return hose.moveAttachments(ids, frames);
}

bool hasClips(const Hose& hose)
{
    for (const Hose::Attachment& a : hose.attachments())
        if (a.isClip()) return true;
    return false;
}

/// Whether every attachment of the hose is within reach of its neighbouring attachments (not
/// clips): for each two consecutive runs, the distance between where their frames put the
/// facing points is at most `share` of the maximum length of the segments between them.
bool withinReach(const Hose& hose, double share)
{
    std::vector<const Hose::Attachment*> runs;
    for (const Hose::Attachment& a : hose.attachments())
        if (!a.isClip()) runs.push_back(&a);
    std::sort(runs.begin(), runs.end(), [](auto* a, auto* b) { return a->first < b->first; });
    for (size_t i = 0; i + 1 < runs.size(); ++i) {
        const Vec3 from = runs[i]->frame.apply(runs[i]->localPoints.back());
        const Vec3 to = runs[i + 1]->frame.apply(runs[i + 1]->localPoints.front());
        double reach = 0.0;
        for (int s = runs[i]->last; s < runs[i + 1]->first; ++s)
            reach += hose.maxLength(s);
        if ((to - from).norm() > share * reach) return false;
    }
    return true;
}

/// Repeats the update at the same frames (the part held still) while measure() reports a
/// problem: at most `updates` times.
void holdStill(Hose& hose, const std::vector<Carried>& carried, const Frame& m, int updates)
{
    for (int n = 0; n < updates && measure(hose).hasProblems(); ++n)
        static_cast<void>(moveTo(hose, carried, m));
}

struct Walk
{
    const char* name;
    Vec3 axis;
    bool turn;
    double step;  ///< metres or radians an update
    double reach; ///< how far out it goes
};

const Walk kWalks[] = {
    {"X", Vec3::UnitX(), false, 0.002, 0.30},
    {"Y", Vec3::UnitY(), false, 0.002, 0.30},
    {"Z", Vec3::UnitZ(), false, 0.002, 0.30},
    {"turn X", Vec3::UnitX(), true, 2.0 * std::numbers::pi / 180.0, std::numbers::pi / 2},
    {"turn Y", Vec3::UnitY(), true, 2.0 * std::numbers::pi / 180.0, std::numbers::pi / 2},
    {"turn Z", Vec3::UnitZ(), true, 2.0 * std::numbers::pi / 180.0, std::numbers::pi / 2},
};

/// Updates a hose may take, held at the same frames, to come back within its limits.
constexpr int kRecoveryUpdates = 32;

void walkSample(const char* name)
{
    const Sample sample = loadSample(name);
    int met = 0, checked = 0, recovered = 0;
    for (size_t part = 0; part < sample.parts.size(); ++part) {
        const auto& [path, carried] = sample.parts[part];
        for (const Walk& walk : kWalks) {
            for (const double sign : {1.0, -1.0}) {
                std::vector<Hose> hoses = sample.hoses;
                const int steps = static_cast<int>(std::lround(walk.reach / walk.step));
                // Out to the far end and back to one step from the start.
                for (int i = 1; i <= 2 * steps - 1; ++i) {
                    const double amount = sign * walk.step * (i <= steps ? i : 2 * steps - i);
                    const Frame m = motion(walk.axis, walk.turn, amount, sample.partOrigins[part]);
                    for (size_t h = 0; h < hoses.size(); ++h) {
                        if (carried[h].empty()) continue;
                        const UpdateResult r = moveTo(hoses[h], carried[h], m);
                        const HoseMetrics metrics = measure(hoses[h]);
                        const std::string where = std::string(name) + " " + path + " " + walk.name +
                                                  " " + std::to_string(amount) + ", hose " +
                                                  sample.definitions[h].id;
                        ASSERT_NE(r.status, Status::InvalidInput) << where;
                        ASSERT_LE(metrics.lengthViolation, 1e-9) << where << ": beyond its band";
                        if (!hasClips(hoses[h]) && withinReach(hoses[h], 0.99)) {
                            ++checked;
                            double gap = 0.0;
                            for (const Carried& c : carried[h])
                                gap = std::max(gap, hoses[h].attachmentGap(c.id));
                            ASSERT_LE(gap, 1e-6) << where << ": within reach, not met";
                            ++met;
                        }
                    }
                }
                // One step from the start: the walked hose and the hose moved there directly.
                const Frame m =
                    motion(walk.axis, walk.turn, sign * walk.step, sample.partOrigins[part]);
                for (size_t h = 0; h < hoses.size(); ++h) {
                    if (carried[h].empty()) continue;
                    const std::string where = std::string(name) + " " + path + " " + walk.name +
                                              (sign > 0 ? " out" : " out the other way") +
                                              " and back, hose " + sample.definitions[h].id;
                    Hose direct = sample.hoses[h];
                    static_cast<void>(moveTo(direct, carried[h], m));
                    if (measure(direct).hasProblems()) continue;
                    // A hose with clips is left out: the clips slid on the way out and a
                    // hose slides only when pulled, so its way back is not the direct one.
                    if (hasClips(hoses[h])) continue;
                    ++recovered;
                    holdStill(hoses[h], carried[h], m, kRecoveryUpdates);
                    const HoseMetrics after = measure(hoses[h]);
                    EXPECT_FALSE(after.hasProblems())
                        << where << ": bend excess " << after.angleViolation << " rad, "
                        << after.bendBelowMinimum.size() << " joints below the minimum bend radius"
                        << " (down to " << after.smallestBendRadius << " m), "
                        << after.unmetAttachments.size() << " attachments unmet, "
                        << after.selfIntersectingSegments.size() << " segments whose rings cross";
                }
            }
        }
    }
    EXPECT_GT(checked, 0) << "no update within reach";
    EXPECT_GT(recovered, 0) << "no walk compared";
    EXPECT_EQ(met, checked);
}

TEST(PartWalks, TheTestRigsPartsMeetTheirHosesWithinReachAndComeBackUnkinked)
{
    walkSample("test-rig.ctproj");
}

TEST(PartWalks, TheMotionRigsPartsMeetTheirHosesWithinReachAndComeBackUnkinked)
{
    walkSample("motion-rig.ctproj");
}

TEST(PartWalks, TheSingleHoseHasNoAttachedPartToWalk)
{
    const Sample sample = loadSample("single-hose.ctproj");
    ASSERT_EQ(sample.hoses.size(), 1u);
    EXPECT_TRUE(sample.hoses[0].attachments().empty());
    EXPECT_TRUE(sample.parts.empty());
}

} // namespace
} // namespace chaintube::formats
