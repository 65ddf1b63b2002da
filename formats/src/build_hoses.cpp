#include "chaintube/formats/collider_exemption.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/material.h"
#include "chaintube/route.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace chaintube::formats {

namespace {

Profile profileOf(const HoseDefinition& hose)
{
    const ProfileSpec& p = hose.profile;
    switch (p.shape) {
    case Profile::Shape::Circle:
        return Profile::circle(0.5 * hose.outerDiameter, p.sides);
    case Profile::Shape::Ellipse:
        return Profile::ellipse(p.semiAxisX, p.semiAxisY, p.sides);
    case Profile::Shape::Rectangle:
        return Profile::rectangle(p.width, p.height);
    case Profile::Shape::RoundedRectangle:
        return Profile::roundedRectangle(p.width, p.height, p.cornerRadius, p.cornerSegments);
    case Profile::Shape::Polygon:
        return Profile::polygon(p.points, p.smoothAngle);
    }
    throw InvalidArgument("hose '" + hose.id + "': unknown profile shape");
}

/// A route this close to a valid shape of its hose (relative length excess beyond the stretch
/// band, radians beyond a bend limit) is taken as the axis as it is.
constexpr double kShapeTolerance = 1e-6;

bool holdsConstraints(const Hose& hose)
{
    const UpdateResult violation = hose.measureViolation();
    return violation.lengthViolation <= kShapeTolerance &&
           violation.angleViolation <= kShapeTolerance;
}

int segmentsForLength(const HoseDefinition& hose, double length)
{
    if (hose.segmentCount > 0) return hose.segmentCount;
    const double count = std::round(length / hose.segmentLength);
    if (!(count <= 1e6))
        throw InvalidArgument("hose '" + hose.id + "': segment length " +
                              std::to_string(hose.segmentLength) +
                              " m gives more than 1,000,000 "
                              "segments for a " +
                              std::to_string(length) + " m hose");
    return std::max(1, static_cast<int>(count));
}

/// Where `segments` steps of chord `chord` from the polyline's first point lead, each step to
/// the first point farther along the polyline at that straight distance from the last: the
/// arc-length position reached (beyond the polyline's length when it ran out) and the points.
double walkChords(const std::vector<Vec3>& polyline, int segments, double chord,
                  std::vector<Vec3>* points)
{
    if (points) points->assign(1, polyline.front());
    Vec3 from = polyline.front();
    size_t leg = 0;   // the polyline segment [leg, leg + 1] the walk is on
    double along = 0; // arc length of polyline[leg]
    Vec3 at = from;   // where on that segment the walk is
    for (int step = 0; step < segments; ++step) {
        for (;;) {
            if (leg + 1 >= polyline.size()) // ran out: count the steps left as overshoot
                return along + chord * (segments - step);
            const Vec3& b = polyline[leg + 1];
            if ((b - from).norm() < chord) { // the whole rest of this leg is nearer: next leg
                along += (b - polyline[leg]).norm();
                at = b;
                ++leg;
                continue;
            }
            // The point at + t (b − at), t ∈ [0, 1], at distance `chord` from `from`.
            const Vec3 d = b - at, f = at - from;
            const double qa = d.squaredNorm(), qb = 2.0 * d.dot(f),
                         qc = f.squaredNorm() - chord * chord;
            const double t =
                qa > 0.0 ? std::clamp((-qb + std::sqrt(std::max(0.0, qb * qb - 4.0 * qa * qc))) /
                                          (2.0 * qa),
                                      0.0, 1.0)
                         : 1.0;
            at = at + t * d;
            break;
        }
        from = at;
        if (points) points->push_back(at);
    }
    return along + (at - polyline[leg]).norm();
}

/// `segments` + 1 points along the polyline from its first to its last point with all chords
/// equal (a hose laid there is at rest with equal rest lengths; equal arc-length samples are
/// shorter on curves). The chord is found by regula falsi (Illinois) on where the walk ends.
std::vector<Vec3> equalChordPoints(const std::vector<Vec3>& polyline, int segments)
{
    const double total = polylineLength(polyline);
    double low = 0.0, high = total / segments; // walks ending short of / at or past the end
    double lowMiss = -total, highMiss = walkChords(polyline, segments, high, nullptr) - total;
    double chord = high;
    int side = 0;
    for (int round = 0;
         round < 100 && std::abs(highMiss) > 1e-14 * total && high - low > 1e-15 * high; ++round) {
        chord = (low * highMiss - high * lowMiss) / (highMiss - lowMiss);
        if (!(chord > low && chord < high)) chord = 0.5 * (low + high);
        const double miss = walkChords(polyline, segments, chord, nullptr) - total;
        if (miss < 0.0) {
            low = chord, lowMiss = miss;
            if (side == -1) highMiss *= 0.5;
            side = -1;
        } else {
            high = chord, highMiss = miss;
            if (side == +1) lowMiss *= 0.5;
            side = +1;
        }
        if (miss == 0.0) break;
    }
    std::vector<Vec3> points;
    walkChords(polyline, segments, high, &points);
    points.resize(static_cast<size_t>(segments) + 1, polyline.back());
    points.back() = polyline.back();
    return points;
}

/// The route with its corners rounded as Hose::alongRoute rounds them (the minimum bend radius,
/// 0.1 % larger so the chords stay inside the bend limit, at most the legs allow).
std::vector<Vec3> roundedRoute(const std::vector<Vec3>& route, const HoseSpec& spec, int segments)
{
    const double rawLength = polylineLength(route);
    const double nominalSegment = rawLength / segments;
    const BendLimit& limit = spec.material.bendLimit;
    double radius = limit.kind == BendLimit::Kind::MinBendRadius
                        ? limit.value
                        : bendRadiusOfTurn(nominalSegment, limit.value);
    radius = std::min(radius * 1.001, 1e3 * rawLength);
    return filletRoute(route, radius, std::max(nominalSegment / 32.0, 1e-9 * rawLength));
}

/// Step 1 of buildHose(): the hose's shape before any attachment, every rest length
/// length / segments.
Hose layOut(const Project& project, const HoseDefinition& definition)
{
    HoseSpec spec = hoseSpecOf(project, definition);
    if (!definition.length) return Hose::alongRoute(definition.route, spec);
    const double length = *definition.length;
    if (!(length > 0.0) || !std::isfinite(length))
        throw InvalidArgument("hose '" + definition.id +
                              "': length: expected a length > 0 m, got " + std::to_string(length));
    const int segments = segmentsForLength(definition, length);
    spec.segmentCount = segments;
    const std::vector<double> rest(static_cast<size_t>(segments), length / segments);
    if (definition.route.size() == static_cast<size_t>(segments) + 1) {
        Hose asLaid = Hose::fromAxis(definition.route, rest, spec);
        if (holdsConstraints(asLaid)) return asLaid;
    }
    spec.validate();
    return Hose::fromAxis(
        equalChordPoints(roundedRoute(definition.route, spec, segments), segments), rest, spec);
}

/// Step 2 of buildHose(): the attachments at the file pose.
void attachAtFilePose(Hose& hose, const HoseDefinition& definition, const ImportedScenes& scenes)
{
    for (const HoseAttachment& attachment : definition.attachments) {
        const auto scene = scenes.find(attachment.scene);
        if (scene == scenes.end())
            throw InvalidArgument("hose '" + definition.id + "': scene '" + attachment.scene +
                                  "' is not imported");
        const int node = scene->second.findNode(attachment.node);
        if (node < 0)
            throw InvalidArgument("hose '" + definition.id + "': scene '" + attachment.scene +
                                  "' has no node '" + attachment.node + "'");
        if (attachment.lastPoint >= hose.pointCount())
            throw InvalidArgument("hose '" + definition.id + "': attachment points [" +
                                  std::to_string(attachment.firstPoint) + ", " +
                                  std::to_string(attachment.lastPoint) + "] outside the hose's " +
                                  std::to_string(hose.pointCount()) + " axis points");
        Frame offset = attachment.offset;
        offset.rotation.normalize();
        hose.attach(attachment.firstPoint, attachment.lastPoint,
                    scene->second.worldFrame(node) * offset);
    }
}

/// The clips of buildHose(), after the attachments and the settle, at the file pose: each where
/// the hose is at its place (Hose::addClip). Errors name the hose and the clip.
void clipAtFilePose(Hose& hose, const HoseDefinition& definition, const ImportedScenes& scenes)
{
    for (size_t c = 0; c < definition.clips.size(); ++c) {
        const HoseClip& clip = definition.clips[c];
        const std::string label = "hose '" + definition.id + "': clip " + std::to_string(c);
        const auto scene = scenes.find(clip.scene);
        if (scene == scenes.end())
            throw InvalidArgument(label + ": scene '" + clip.scene + "' is not imported");
        const int node = scene->second.findNode(clip.node);
        if (node < 0)
            throw InvalidArgument(label + ": scene '" + clip.scene + "' has no node '" + clip.node +
                                  "'");
        Frame offset = clip.offset;
        offset.rotation.normalize();
        ClipOptions options;
        options.hold = clip.hold;
        if (clip.slideMin) options.slideMin = *clip.slideMin;
        if (clip.slideMax) options.slideMax = *clip.slideMax;
        try {
            (void)hose.addClip(clip.place, scene->second.worldFrame(node) * offset, options);
        } catch (const InvalidArgument& e) {
            throw InvalidArgument(label + ": " + e.what());
        }
    }
}

/// Step 3 of buildHose() (and withLength()): settle() with the route's two ends held where
/// they are (a hose that gets longer bows between them instead of reaching past the end);
/// when it cannot reach, the last point is let go unless an attachment holds it.
UpdateResult settleBetweenRouteEnds(Hose& hose)
{
    std::vector<int> pins;
    const int last = hose.pointCount() - 1;
    if (!hose.isFixed(0)) pins.push_back(hose.attach(0, 0, Frame::identity()));
    int endPin = -1;
    if (!hose.isFixed(last)) {
        endPin = hose.attach(last, last, Frame::identity());
        pins.push_back(endPin);
    }
    UpdateResult result = hose.settle();
    if (!result.ok() && endPin >= 0) {
        hose.detach(endPin);
        pins.pop_back();
        result = hose.settle();
    }
    for (int pin : pins)
        hose.detach(pin);
    return result;
}

/// Node index of every pose of the project in scene `sceneId` (−1 entries never occur: an
/// unknown node path throws).
std::vector<std::pair<int, const NodePose*>>
posesOfScene(const Project& project, const ImportedScenes& scenes, const std::string& sceneId)
{
    std::vector<std::pair<int, const NodePose*>> found;
    for (size_t i = 0; i < project.poses.size(); ++i) {
        const NodePose& pose = project.poses[i];
        if (pose.scene != sceneId) continue;
        const auto scene = scenes.find(pose.scene);
        const int node = scene == scenes.end() ? -1 : scene->second.findNode(pose.node);
        if (node < 0)
            throw InvalidArgument("pose " + std::to_string(i) + " (/poses/" + std::to_string(i) +
                                  "): scene '" + pose.scene + "' has no node '" + pose.node + "'");
        found.emplace_back(node, &pose);
    }
    return found;
}

/// Steps 1 to 3 of buildHose() and its clips, at the file pose (no pose overrides).
Hose buildAtFilePose(const Project& project, const HoseDefinition& definition,
                     const ImportedScenes& scenes, UpdateResult* lastUpdate)
{
    Hose hose = layOut(project, definition);
    attachAtFilePose(hose, definition, scenes);
    if (definition.length && !holdsConstraints(hose)) {
        const UpdateResult settled = settleBetweenRouteEnds(hose);
        if (lastUpdate) *lastUpdate = settled;
    }
    clipAtFilePose(hose, definition, scenes);
    return hose;
}

/// Where a clip holds the hose, in world metres: its centre and its unit axis.
struct ClipHold
{
    Vec3 centre = Vec3::Zero();
    Vec3 axis = Vec3::UnitX();
};

/// The clips of `hose` (built by buildAtFilePose: the attachments first, then the clips in the
/// definition's order) as world centres and axes.
std::vector<ClipHold> clipHolds(const Hose& hose, size_t attachmentCount)
{
    std::vector<ClipHold> holds;
    for (size_t a = attachmentCount; a < hose.attachments().size(); ++a) {
        const Hose::Attachment& clip = hose.attachments()[a];
        holds.push_back({clip.frame.apply(clip.clipCentre), clip.frame.rotation * clip.clipAxis});
    }
    return holds;
}

/// withLength()'s relative margins, one attempt each: a piece of hose between two held points
/// within half of one of its straight line is short, and a short piece is given its straight
/// line plus it (as the library's clips feed a short side, lib/README.md "Clips").
constexpr double kClipPieceMargins[] = {0.01, 0.05, 0.15};
/// Rounds of fitClipPlaces' redistribution after the first (each piece's straight line depends
/// on where the clips' held segments are).
constexpr int kClipPlaceRounds = 4;

/// withLength()'s clip places on `laid` (the hose at its new length, attachments fixed, no
/// clips yet), `holds` where the clips are. Each clip's place and end stops are scaled by
/// `scale` (new length / old). Then, for each run of clips between two consecutive fixed
/// points, the pieces of hose between consecutive held points (the fixed points, the clips'
/// centres) are measured against their straight lines (through the ends of the segments the
/// clips hold along their axes, as the library measures a clip's side; a free end demands
/// nothing). When a piece is short (within half of `pieceMargin` of its straight line) the
/// hose slides through the clips: every piece below its straight line plus the margin (less,
/// the same fraction for every piece, when the run has not that much to spare; below 0 when it
/// is shorter than its straight lines and cannot pass through the clips) is given that, the
/// rest taken from the other pieces in proportion to what they have beyond it. The places then
/// stay within their end stops and off the fixed points.
void fitClipPlaces(const Hose& laid, HoseDefinition& changed, const std::vector<ClipHold>& holds,
                   double scale, double pieceMargin)
{
    const int n = laid.segmentCount();
    const double total = laid.restLengthTotal();
    const double segment = total / n; // withLength's rest lengths are equal
    std::vector<double> place, low, high;
    for (HoseClip& clip : changed.clips) {
        if (clip.slideMin) clip.slideMin = *clip.slideMin * scale;
        if (clip.slideMax) clip.slideMax = std::min(total, *clip.slideMax * scale);
        low.push_back(clip.slideMin.value_or(0.0));
        high.push_back(clip.slideMax.value_or(total));
        place.push_back(std::clamp(clip.place * scale, low.back(), high.back()));
    }
    std::vector<size_t> order(changed.clips.size());
    for (size_t c = 0; c < order.size(); ++c)
        order[c] = c;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return place[a] < place[b]; });
    // The ends of the segment a clip at place s holds: along its axis about its centre.
    const auto heldEnd = [&](size_t c, double s, bool far) {
        const double f = s / segment - std::min(std::floor(s / segment), n - 1.0);
        return Vec3(holds[c].centre + ((far ? 1.0 - f : -f) * segment) * holds[c].axis);
    };
    for (size_t begin = 0; begin < order.size();) {
        // The run: the clips between the fixed points `before` and `after` (−1, n + 1: none).
        int before = std::min(n, static_cast<int>(std::floor(place[order[begin]] / segment)));
        while (before >= 0 && !laid.isFixed(before))
            --before;
        int after = before + 1;
        while (after <= n && !laid.isFixed(after))
            ++after;
        size_t end = begin;
        while (end < order.size() && place[order[end]] <= after * segment)
            ++end;
        const double start = before >= 0 ? before * segment : 0.0;
        const double finish = after <= n ? after * segment : total;
        // Piece k runs from held point k − 1 to held point k of the run (k = 0: from `before`;
        // k = clips: to `after`); its rest length with the scaled places.
        const size_t clips = end - begin;
        std::vector<double> scaled(clips + 1);
        for (size_t k = 0; k <= clips; ++k)
            scaled[k] = (k == clips ? finish : place[order[begin + k]]) -
                        (k == 0 ? start : place[order[begin + k - 1]]);
        std::vector<double> at(clips); // the places of this round
        for (size_t k = 0; k < clips; ++k)
            at[k] = place[order[begin + k]];
        // Each round measures the straight lines with the clips' segments where `at` puts them
        // and redistributes the scaled pieces by them; the places whose own pieces have the
        // most to spare (relative to their straight lines) are kept: a clip's segment changes
        // when its place crosses a point, and with it the straight lines.
        std::vector<double> best = at;
        double bestSpare = -std::numeric_limits<double>::infinity();
        for (int round = 0; round <= kClipPlaceRounds; ++round) {
            std::vector<double> demand(clips + 1, 0.0);
            double demanded = 0.0, spareOfAt = std::numeric_limits<double>::infinity();
            for (size_t k = 0; k <= clips; ++k) {
                if ((k == 0 && before < 0) || (k == clips && after > n)) continue; // a free end
                const size_t from = k == 0 ? 0 : order[begin + k - 1];
                const size_t to = k == clips ? 0 : order[begin + k];
                // From a clip's centre along its axis to the end of its segment, then straight.
                const Vec3 a = k == 0 ? laid.point(before) : heldEnd(from, at[k - 1], true);
                const Vec3 b = k == clips ? laid.point(after) : heldEnd(to, at[k], false);
                demand[k] = (b - a).norm() + (k == 0 ? 0.0 : (a - holds[from].centre).norm()) +
                            (k == clips ? 0.0 : (holds[to].centre - b).norm());
                demanded += demand[k];
                const double piece = (k == clips ? finish : at[k]) - (k == 0 ? start : at[k - 1]);
                spareOfAt = std::min(spareOfAt, piece / std::max(demand[k], 1e-12 * total) - 1.0);
            }
            if (spareOfAt > bestSpare) best = at, bestSpare = spareOfAt;
            bool isShort = false;
            for (size_t k = 0; k <= clips; ++k)
                isShort = isShort || scaled[k] < demand[k] * (1.0 + 0.5 * pieceMargin);
            if (!isShort || round == kClipPlaceRounds) break;
            const double margin = std::min(pieceMargin, (finish - start) / demanded - 1.0);
            double raised = 0.0, spare = 0.0;
            for (size_t k = 0; k <= clips; ++k) {
                const double target = demand[k] * (1.0 + margin);
                (scaled[k] < target ? raised : spare) += std::abs(scaled[k] - target);
            }
            std::vector<double> next(clips);
            double along = start;
            for (size_t k = 0; k < clips; ++k) {
                const double target = demand[k] * (1.0 + margin);
                along +=
                    scaled[k] < target
                        ? target
                        : scaled[k] - (spare > 0.0 ? raised * (scaled[k] - target) / spare : 0.0);
                next[k] = along;
            }
            if (next == at) break;
            at = next;
        }
        at = best;
        // Within the end stops, and the segment holding each clip off the fixed points and off
        // the previous clip's segment (a hair inside, so that rounding picks the same segment).
        const double inset = 1e-9 * segment;
        double least = (before + 1) * segment + inset;
        for (size_t k = 0; k < clips; ++k) {
            const size_t c = order[begin + k];
            const double most = std::min(high[c], (after - 1) * segment - inset);
            place[c] = std::clamp(std::max(at[k], least), low[c], std::max(low[c], most));
            least = (std::floor(place[c] / segment) + 2.0) * segment + inset;
        }
        begin = end;
    }
    for (size_t c = 0; c < changed.clips.size(); ++c)
        changed.clips[c].place = place[c];
}

/// `points` with each run of free points between two pinned points of `pinned` laid straight
/// between them, evenly.
std::vector<Vec3> straightBetweenPins(const std::vector<Vec3>& points, const Hose& pinned)
{
    std::vector<Vec3> straight = points;
    int last = -1;
    for (int i = 0; i < pinned.pointCount(); ++i) {
        if (!pinned.isFixed(i)) continue;
        const Vec3 from = last >= 0 ? points[static_cast<size_t>(last)] : Vec3::Zero();
        for (int k = last + 1; last >= 0 && k < i; ++k)
            straight[static_cast<size_t>(k)] = from + (static_cast<double>(k - last) / (i - last)) *
                                                          (points[static_cast<size_t>(i)] - from);
        last = i;
    }
    return straight;
}

/// withLength() for a hose with clips: `changed` has its new length and attachments, `points`
/// the shape to lay it from (one per axis point), `rest` the new rest lengths, `scale` new
/// length / old. For each margin of kClipPieceMargins (the library's, lib/README.md "Clips")
/// the clip places are fitted (fitClipPlaces), the segment holding each clip laid through the
/// clip's centre along its axis, and the hose settled inextensibly with its attachments and
/// clips held, from where it lies and, failing that, from each piece laid straight between its
/// held points (near taut the settle's budget may not reach a valid shape from farther off; a
/// straight piece longer than its chord is bowed first). The first shape that buildHose takes
/// as it is (valid with the hose's own material, `actual`) is the result; if none is, the
/// first margin's.
HoseDefinition layThroughClips(const Project& project, const HoseDefinition& hose,
                               const HoseDefinition& changed, const ImportedScenes& scenes,
                               const std::vector<Vec3>& points, const std::vector<double>& rest,
                               const HoseSpec& inextensible, const HoseSpec& actual, double scale)
{
    // The clips stay where they are (their parts do not move).
    const std::vector<ClipHold> holds =
        clipHolds(buildAtFilePose(project, hose, scenes, nullptr), hose.attachments.size());
    const double segment = rest.front();
    std::optional<HoseDefinition> fallback;
    for (const double margin : kClipPieceMargins) {
        HoseDefinition attempt = changed;
        Hose laid = Hose::fromAxis(points, rest, inextensible);
        attachAtFilePose(laid, attempt, scenes);
        fitClipPlaces(laid, attempt, holds, scale, margin);
        clipAtFilePose(laid, attempt, scenes); // which segment holds each clip
        std::vector<Vec3> through = points;
        for (size_t c = 0; c < attempt.clips.size(); ++c) {
            const Hose::Attachment& clip = laid.attachments()[attempt.attachments.size() + c];
            const double f =
                std::clamp((attempt.clips[c].place - clip.first * segment) / segment, 0.0, 1.0);
            through[static_cast<size_t>(clip.first)] =
                holds[c].centre - (f * segment) * holds[c].axis;
            through[static_cast<size_t>(clip.last)] =
                holds[c].centre + ((1.0 - f) * segment) * holds[c].axis;
        }
        for (const bool straight : {false, true}) {
            Hose settled = Hose::fromAxis(straight ? straightBetweenPins(through, laid) : through,
                                          rest, inextensible);
            attachAtFilePose(settled, attempt, scenes);
            clipAtFilePose(settled, attempt, scenes); // held like attachments while it settles
            // Its status shows in the hose built from the result (measure(), attachmentGap).
            static_cast<void>(settleBetweenRouteEnds(settled));
            attempt.route = settled.points();
            if (holdsConstraints(Hose::fromAxis(attempt.route, rest, actual))) return attempt;
            if (!fallback) fallback = attempt;
        }
    }
    return *fallback;
}

} // namespace

std::shared_ptr<MeshCollider> nodeCollider(const ImportedScene& scene, int node, const Mat4& world)
{
    const SceneNode& sceneNode = scene.nodes.at(static_cast<size_t>(node));
    const Frame frame = rigidPart(world);
    std::vector<Vec3> positions;
    std::vector<std::uint32_t> indices;
    for (int meshIndex : sceneNode.meshes) {
        const SceneMesh& mesh = scene.meshes[static_cast<size_t>(meshIndex)];
        const auto base = static_cast<std::uint32_t>(positions.size());
        for (size_t v = 0; v < mesh.vertexCount(); ++v) {
            const Vec3 local(mesh.positions[3 * v], mesh.positions[3 * v + 1],
                             mesh.positions[3 * v + 2]);
            positions.push_back(frame.applyInverse((world * local.homogeneous()).head<3>()));
        }
        for (std::uint32_t index : mesh.indices)
            indices.push_back(base + index);
    }
    if (indices.empty()) return nullptr;
    return MeshCollider::fromArrays(positions, indices, frame);
}

Mat4 posedWorldTransform(const Project& project, const ImportedScenes& scenes,
                         const std::string& sceneId, int node)
{
    const auto scene = scenes.find(sceneId);
    if (scene == scenes.end()) throw InvalidArgument("scene '" + sceneId + "' is not imported");
    const std::vector<SceneNode>& nodes = scene->second.nodes;
    if (node < 0 || node >= static_cast<int>(nodes.size()))
        throw InvalidArgument("scene '" + sceneId + "' has no node " + std::to_string(node));
    const auto poses = posesOfScene(project, scenes, sceneId);
    Mat4 world = Mat4::Identity();
    for (int n = node; n >= 0; n = nodes[static_cast<size_t>(n)].parent) {
        Mat4 local = nodes[static_cast<size_t>(n)].localTransform;
        for (const auto& [posedNode, pose] : poses)
            if (posedNode == n) local = pose->localTransform;
        world = local * world;
    }
    return world;
}

ImportedScenes posedScenes(const Project& project, ImportedScenes scenes)
{
    for (const SceneReference& reference : project.scenes) {
        const auto poses = posesOfScene(project, scenes, reference.id);
        for (const auto& [node, pose] : poses)
            scenes.at(reference.id).nodes[static_cast<size_t>(node)].localTransform =
                pose->localTransform;
    }
    for (size_t i = 0; i < project.poses.size(); ++i)
        if (!project.findScene(project.poses[i].scene))
            throw InvalidArgument("pose " + std::to_string(i) + ": unknown scene '" +
                                  project.poses[i].scene + "'");
    return scenes;
}

ImportedScenes importProjectScenes(const Project& project, const std::filesystem::path& projectFile,
                                   const NamedRoots& roots,
                                   const std::function<bool(double)>& progress)
{
    ImportedScenes scenes;
    const double count = static_cast<double>(project.scenes.size());
    for (size_t i = 0; i < project.scenes.size(); ++i) {
        const SceneReference& reference = project.scenes[i];
        ImportOptions options;
        options.metresPerUnit = reference.import.metresPerUnit;
        options.upAxis = reference.import.upAxis;
        options.chordalTolerance = reference.import.chordalTolerance;
        options.angularTolerance = reference.import.angularTolerance;
        if (progress)
            options.progress = [&](double fraction) {
                return progress((static_cast<double>(i) + fraction) / count);
            };
        ImportedScene scene = importScene(resolveScenePath(reference, projectFile, roots), options);
        placeScene(scene, reference.import.placement);
        scenes.emplace(reference.id, std::move(scene));
    }
    return scenes;
}

void placeScene(ImportedScene& scene, const Vec3& placement)
{
    if (!scene.nodes.empty()) scene.nodes[0].localTransform.block<3, 1>(0, 3) += placement;
}

HoseSpec hoseSpecOf(const Project& project, const HoseDefinition& hose)
{
    HoseSpec spec;
    spec.outerDiameter = hose.outerDiameter;
    spec.material = project.materialOf(hose);
    spec.segmentCount = hose.segmentCount;
    spec.segmentLength = hose.segmentLength;
    spec.profile = profileOf(hose);
    spec.gravity = hose.gravity;
    spec.torsion = hose.torsion;
    return spec;
}

double routeRestLength(const Project& project, const HoseDefinition& hose)
{
    const HoseSpec spec = hoseSpecOf(project, hose);
    const int segments = Hose::alongRoute(hose.route, spec).segmentCount();
    // An axis of the hose (a committed drag, a generated sample): as long as it is, when it is
    // a valid shape at its mean chord.
    if (hose.route.size() == static_cast<size_t>(segments) + 1) {
        const double length = polylineLength(hose.route);
        HoseSpec counted = spec;
        counted.segmentCount = segments;
        const Hose asLaid = Hose::fromAxis(
            hose.route, std::vector<double>(static_cast<size_t>(segments), length / segments),
            counted);
        if (holdsConstraints(asLaid)) return length;
    }
    const std::vector<Vec3> points =
        equalChordPoints(roundedRoute(hose.route, spec, segments), segments);
    return segments * (points[1] - points[0]).norm();
}

double hoseLength(const Project& project, const HoseDefinition& hose)
{
    return hose.length ? *hose.length : routeRestLength(project, hose);
}

UpdateResult moveAttachmentsFully(Hose& hose, const std::vector<int>& ids,
                                  const std::vector<Frame>& frames)
{
    std::vector<Frame> from;
    for (const int id : ids)
        for (const Hose::Attachment& attachment : hose.attachments())
            if (attachment.id == id) from.push_back(attachment.frame);
    UpdateResult result = hose.moveAttachments(ids, frames);
    const auto short_ = [&] {
        double gap = 0.0;
        for (const int id : ids)
            gap = std::max(gap, hose.attachmentGap(id));
        return gap > 1e-9;
    };
    if (result.status != Status::Infeasible || !short_() || from.size() != frames.size())
        return result;
    std::vector<Frame> step(frames.size());
    for (int k = 1; k <= kPoseSubSteps; ++k) {
        const double t = double(k) / kPoseSubSteps;
        for (size_t i = 0; i < frames.size(); ++i) {
            step[i].translation =
                from[i].translation + t * (frames[i].translation - from[i].translation);
            step[i].rotation = from[i].rotation.slerp(t, frames[i].rotation);
        }
        result = hose.moveAttachments(ids, step);
    }
    for (int again = 0; again < kPoseSubSteps && result.status == Status::Infeasible && short_() &&
                        result.movedPoints > 0;
         ++again)
        result = hose.moveAttachments(ids, frames);
    return result;
}

Hose buildHose(const Project& project, const HoseDefinition& definition,
               const ImportedScenes& scenes, UpdateResult* lastUpdate)
{
    if (lastUpdate) *lastUpdate = UpdateResult();
    Hose hose = buildAtFilePose(project, definition, scenes, lastUpdate);
    // Pose overrides: the attachments and clips go to the posed frames from the file pose (the
    // editor's Document builds a hose so whenever a part moves). hose.attachments() holds the
    // attachments, then the clips, in the definition's order.
    struct Held
    {
        const std::string* scene;
        const std::string* node;
        Frame offset;
    };
    std::vector<Held> held;
    for (const HoseAttachment& attachment : definition.attachments)
        held.push_back({&attachment.scene, &attachment.node, attachment.offset});
    for (const HoseClip& clip : definition.clips)
        held.push_back({&clip.scene, &clip.node, clip.offset});
    bool posed = false;
    for (const Held& h : held) {
        const ImportedScene& scene = scenes.at(*h.scene);
        for (const auto& [posedNode, pose] : posesOfScene(project, scenes, *h.scene))
            for (int n = scene.findNode(*h.node); n >= 0 && !posed;
                 n = scene.nodes[static_cast<size_t>(n)].parent)
                posed = n == posedNode;
    }
    if (posed) {
        std::vector<int> ids;
        std::vector<Frame> frames;
        for (size_t a = 0; a < held.size(); ++a) {
            Frame offset = held[a].offset;
            offset.rotation.normalize();
            const int node = scenes.at(*held[a].scene).findNode(*held[a].node);
            ids.push_back(hose.attachments()[a].id);
            frames.push_back(rigidPart(posedWorldTransform(project, scenes, *held[a].scene, node)) *
                             offset);
        }
        const UpdateResult moved = moveAttachmentsFully(hose, ids, frames);
        // Without a caller that asks, the hose itself keeps what the move could not do:
        // measure() and Hose::attachmentGap report it to whoever draws or exports it.
        if (lastUpdate) *lastUpdate = moved;
    }
    return hose;
}

namespace {

/// The attachments of a hose of `before` segments carried over to `segments` (see
/// withSegmentCount); false, with `clash` the indices of two that would share points, if they
/// would.
bool remapAttachments(std::vector<HoseAttachment>& attachments, int before, int segments,
                      std::pair<size_t, size_t>* clash)
{
    const auto map = [&](int point) {
        return static_cast<int>(std::lround(static_cast<double>(point) * segments / before));
    };
    for (HoseAttachment& attachment : attachments) {
        const int width = attachment.lastPoint > attachment.firstPoint ? 1 : 0;
        const bool atEnd = attachment.lastPoint >= before;
        int first = std::clamp(map(attachment.firstPoint), 0, segments);
        int last = std::clamp(map(attachment.lastPoint), 0, segments);
        if (atEnd) last = segments;
        if (last - first < width) {
            if (last + width <= segments && !atEnd)
                last = first + width;
            else
                first = last - width;
        }
        attachment.firstPoint = std::max(0, first);
        attachment.lastPoint = last;
    }
    for (size_t a = 0; a < attachments.size(); ++a)
        for (size_t b = a + 1; b < attachments.size(); ++b)
            if (attachments[a].firstPoint <= attachments[b].lastPoint &&
                attachments[b].firstPoint <= attachments[a].lastPoint) {
                if (clash) *clash = {a, b};
                return false;
            }
    return true;
}

} // namespace

HoseDefinition withSegmentCount(const Project& project, const HoseDefinition& hose, int segments)
{
    if (segments < 1 || segments > 1000000)
        throw InvalidArgument("hose '" + hose.id +
                              "': resolution: expected 1 … 1,000,000 segments, got " +
                              std::to_string(segments));
    const int before = segmentsForLength(hose, hoseLength(project, hose));
    HoseDefinition result = hose;
    result.segmentCount = segments;
    if (segments == before) return result;
    std::pair<size_t, size_t> clash;
    if (!remapAttachments(result.attachments, before, segments, &clash)) {
        std::string fewest = "more";
        for (int n = segments + 1; n <= std::max(before, segments + 1000); ++n) {
            std::vector<HoseAttachment> trial = hose.attachments;
            if (remapAttachments(trial, before, n, nullptr)) {
                fewest = "at least " + std::to_string(n);
                break;
            }
        }
        const auto describe = [&](size_t i) {
            const HoseAttachment& a = hose.attachments[i];
            return "the fixed points " + std::to_string(a.firstPoint) + "–" +
                   std::to_string(a.lastPoint) + " on " + a.node;
        };
        throw InvalidArgument("hose '" + hose.id + "': " + std::to_string(segments) +
                              " segments are too few for its fixed points: " +
                              describe(clash.first) + " and " + describe(clash.second) +
                              " would share axis points; " + fewest + " segments keep them apart");
    }
    return result;
}

HoseDefinition withLength(const Project& project, const HoseDefinition& hose,
                          const ImportedScenes& scenes, double length)
{
    if (!(length > 0.0) || !std::isfinite(length))
        throw InvalidArgument("hose '" + hose.id + "': length: expected a length > 0 m, got " +
                              std::to_string(length));
    Hose current = layOut(project, hose);
    attachAtFilePose(current, hose, scenes);
    HoseDefinition changed = hose;
    changed.length = length;
    const int segments = segmentsForLength(hose, length);
    std::vector<Vec3> points = current.points();
    if (segments != current.segmentCount()) {
        points = resampleByArcLength(points, segments);
        const int shift = segments - current.segmentCount();
        for (HoseAttachment& attachment : changed.attachments)
            if (attachment.lastPoint == current.segmentCount()) {
                attachment.firstPoint = std::max(0, attachment.firstPoint + shift);
                attachment.lastPoint += shift;
            }
        for (size_t a = 0; a < changed.attachments.size(); ++a)
            for (size_t b = 0; b < a; ++b)
                if (changed.attachments[a].firstPoint <= changed.attachments[b].lastPoint &&
                    changed.attachments[b].firstPoint <= changed.attachments[a].lastPoint)
                    throw InvalidArgument("hose '" + hose.id + "': at " + std::to_string(length) +
                                          " m its " + std::to_string(segments) +
                                          " segments leave no room between its attachments");
    }
    // Settled with no stretch: the new length shows where it goes (as slack between the
    // held ends, or pulled in), not as segments compressed or stretched within their band.
    HoseSpec inextensible = hoseSpecOf(project, hose);
    inextensible.segmentCount = segments;
    inextensible.material.expansionCoefficient = 0.0;
    const std::vector<double> rest(static_cast<size_t>(segments), length / segments);
    if (!hose.clips.empty()) {
        HoseSpec actual = hoseSpecOf(project, hose);
        actual.segmentCount = segments;
        return layThroughClips(project, hose, changed, scenes, points, rest, inextensible, actual,
                               length / current.restLengthTotal());
    }
    Hose laid = Hose::fromAxis(points, rest, inextensible);
    attachAtFilePose(laid, changed, scenes);
    // Its status shows in the hose built from the result (measure(), Hose::attachmentGap).
    static_cast<void>(settleBetweenRouteEnds(laid));
    changed.route = laid.points();
    return changed;
}

bool attachmentsExempt(const HoseDefinition& hose, const std::string& sceneId,
                       const std::string& nodePath)
{
    return std::any_of(hose.attachments.begin(), hose.attachments.end(),
                       [&](const HoseAttachment& a) {
                           return a.scene == sceneId && attachmentExemptsPath(a.node, nodePath);
                       }) ||
           std::any_of(hose.clips.begin(), hose.clips.end(), [&](const HoseClip& c) {
               return c.scene == sceneId && attachmentExemptsPath(c.node, nodePath);
           });
}

int settleUnderGravity(Hose& hose, const HoseDefinition& definition, const Project& project,
                       const ImportedScenes& scenes, int stepBudget)
{
    if (!hose.spec().gravity.enabled) return 0;
    std::vector<std::shared_ptr<const MeshCollider>> used;
    for (const ColliderNode& collider : project.colliders) {
        const auto scene = scenes.find(collider.scene);
        if (scene == scenes.end() || attachmentsExempt(definition, collider.scene, collider.node))
            continue;
        const int node = scene->second.findNode(collider.node);
        if (node < 0) continue;
        if (std::shared_ptr<MeshCollider> mesh = nodeCollider(
                scene->second, node, posedWorldTransform(project, scenes, collider.scene, node)))
            used.push_back(std::move(mesh));
    }
    hose.setColliders(std::move(used));
    int steps = 0;
    while (steps < stepBudget && hose.step().movedPoints > 0)
        ++steps;
    hose.setColliders({});
    hose.markSettled();
    return steps;
}

std::vector<Hose> buildHoses(const Project& project, const ImportedScenes& scenes)
{
    std::vector<Hose> hoses;
    hoses.reserve(project.hoses.size());
    for (const HoseDefinition& definition : project.hoses)
        hoses.push_back(buildHose(project, definition, scenes));
    return hoses;
}

} // namespace chaintube::formats
