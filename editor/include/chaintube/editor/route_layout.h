// ChainTube editor — laying out a new hose by clicks: where a clicked route point goes and the
// size a new hose starts with. Plain functions over the core library's types (no Qt), so they
// are tested without a window; the viewport and the main window call them. The rules and
// their figures are in editor/README.md ("Laying out a new hose").
#pragma once

#include "chaintube/editor/camera.h"
#include "chaintube/material.h"

#include <functional>
#include <vector>

namespace chaintube::editor {

/// A route point placed off a clicked surface.
struct SurfaceOffset
{
    Vec3 position = Vec3::Zero();    ///< the route point (world metres)
    Vec3 direction = Vec3::UnitY();  ///< unit direction it went out along from the surface
    bool alongSurfaceNormal = false; ///< false: no usable normal, it went towards the camera
};

/// Where a route point clicked on a surface goes: `distance` metres (≥ 0; a new hose's outer
/// radius plus the clearance) out from the surface point `surfacePoint` along the surface
/// normal, on the side the click came from. `normal` is the surface normal at the hit (any
/// length, either orientation); `viewDirection` the direction of the picking ray (camera to
/// surface, any length). Decided cases:
///  * a normal facing away from the camera (a back face hit, or a mesh wound inside out) is
///    flipped, so the point always goes out on the side that was clicked;
///  * a zero or non-finite normal (a degenerate triangle, a node scaled to nothing) is
///    replaced by −viewDirection: the point goes back towards the camera along the ray;
///  * a zero or non-finite viewDirection keeps the normal's own orientation; with no normal
///    either, the point goes up (+Y, the project's up axis).
/// A negative or non-finite distance counts as 0 (the point stays on the surface).
SurfaceOffset offsetFromSurface(const Vec3& surfacePoint, const Vec3& normal,
                                const Vec3& viewDirection, double distance);

/// The nearest surface point to a position, as a scene query answers it (found false: no
/// surface nearer than the query's distance).
struct NearestSurface
{
    bool found = false;
    Vec3 point = Vec3::Zero(); ///< on the surface (world metres)
};
/// Answers the nearest surface point to `position` among those nearer than `maxDistance`.
using NearestSurfaceQuery = std::function<NearestSurface(const Vec3& position, double maxDistance)>;

/// Pushes of keepClearOfSurfaces at most (each one query).
inline constexpr int kMaxClearingPushes = 16;

/// A route point moved off every surface near it.
struct ClearedRoutePoint
{
    Vec3 position = Vec3::Zero();
    /// Distance to the nearest surface there (metres; the wanted distance or more when `clear`;
    /// `distance` itself when no surface is within it).
    double clearance = 0.0;
    bool clear = false; ///< every surface is at least the wanted distance away
    int pushes = 0;     ///< pushes made (≤ kMaxClearingPushes)
};

/// A route point placed by offsetFromSurface keeps `distance` from the clicked surface, but a
/// point clicked near an inner corner or in a groove can still be nearer another face of the
/// same part or a neighbouring part. This moves it on until no surface `nearest` knows is nearer
/// than `distance`: each push moves it away from the nearest surface point by what is missing
/// (along the surface point's direction; a point on the surface itself goes along
/// `placed.direction`), at most kMaxClearingPushes pushes. From the second push on, the
/// previous push's surface (as its tangent plane) is solved with the new one, so the point
/// moves along it rather than back towards it: an inner corner or a wedge of two faces is
/// cleared in one or two pushes. A gap narrower than 2 × `distance`
/// cannot be cleared: the point with the largest clearance found is returned, `clear` false.
/// A null query, or a negative or non-finite distance, leaves the point where it is.
ClearedRoutePoint keepClearOfSurfaces(const SurfaceOffset& placed, double distance,
                                      const NearestSurfaceQuery& nearest);

/// Route points keepRouteClearOfSurfaces() adds at most.
inline constexpr int kMaxAddedRoutePoints = 12;
/// An added route point keeps this many times the distance from the surfaces near it, so that
/// the legs to its neighbours, which cut the corner it goes round, keep the distance too.
inline constexpr double kAddedRoutePointMargin = 1.25;

/// A route whose hose keeps clear of every surface near it.
struct ClearedRoute
{
    std::vector<Vec3> route;
    /// For each point of `route`, the index of the point it was in the route given, or −1 for
    /// a point added between two of them.
    std::vector<int> given;
    int added = 0;
    /// The smallest distance from an axis point (or a segment's middle) to a surface, metres
    /// (`distance` when no surface is within it).
    double clearance = 0.0;
    bool clear = false; ///< every axis point and segment middle keeps `distance`
};

/// A route's points keep `distance` from every surface (keepClearOfSurfaces), but the hose
/// laid between them can pass nearer another part: a leg along a part's edge, an arc that cuts
/// the corner over a bracket. This lays the hose (`axisOf`: the axis points of the hose laid
/// along a route), finds the axis point or segment middle nearest a surface and, where it is
/// nearer than `distance` (to 1e-6 of it), adds a route point there, pushed clear with
/// keepClearOfSurfaces to kAddedRoutePointMargin × `distance`, between the two route points
/// whose leg it lies on; then lays the hose again, at most kMaxAddedRoutePoints times. The given
/// points are never moved, and no point is added that leaves the corners less room for arcs of
/// `bendRadius` (metres, as tightCorners() shares the legs): there the clicks leave the hose no
/// way round that keeps its bend radius. `clear` false: the hose could not be laid clear (a gap
/// narrower than the hose, a way round too tight, or the budget spent); the route with the
/// largest clearance found is returned. A null query or axisOf leaves the route.
ClearedRoute
keepRouteClearOfSurfaces(const std::vector<Vec3>& route, double distance, double bendRadius,
                         const std::function<std::vector<Vec3>(const std::vector<Vec3>&)>& axisOf,
                         const NearestSurfaceQuery& nearest);

/// Added to the distance a clicked route point goes out (metres): a hose laid along a flat face
/// then keeps at least the clearance after rounding, and a check at exactly that threshold
/// does not list it.
inline constexpr double kRouteClearanceMargin = 1e-6;

/// How far (metres) a route point clicked on a surface goes out from it for a hose of outer
/// diameter `outerDiameter` that keeps `clearance` from the surface (both metres; a negative
/// or non-finite clearance counts as 0): outerDiameter / 2 + clearance + kRouteClearanceMargin.
double routePointDistance(double outerDiameter, double clearance);

/// Outer diameter (metres) a new hose starts with when nothing tells the size of the scene,
/// and the size the standard material presets are written for.
inline constexpr double kFallbackHoseDiameter = 0.02;
/// Smallest and largest default outer diameter (metres).
inline constexpr double kMinDefaultHoseDiameter = 0.002;
inline constexpr double kMaxDefaultHoseDiameter = 0.05;
/// The default diameter is this fraction of the scene's bounding-box diagonal before rounding.
inline constexpr double kHoseDiameterPerSceneDiagonal = 1.0 / 50.0;
/// Minimum bend radius of a new hose as a multiple of its outer diameter (the "PVC hose"
/// preset's 100 mm for 20 mm; hose datasheets give 4 to 6 for thermoplastic hoses).
inline constexpr double kBendRadiusPerDiameter = 5.0;
/// A preset's bend radius counts as suited to a diameter D when it lies in
/// [kMinPresetBendRadiusPerDiameter·D, kMaxPresetBendRadiusPerDiameter·D]: the four standard
/// presets (4 to 8.25 × 20 mm) all suit a 20 mm hose.
inline constexpr double kMinPresetBendRadiusPerDiameter = 4.0;
inline constexpr double kMaxPresetBendRadiusPerDiameter = 10.0;
/// Longest axis segment of a new hose (metres) and its number of segments.
inline constexpr double kMaxNewSegmentLength = 0.03;
inline constexpr int kMinNewSegmentCount = 12;
inline constexpr int kMaxNewSegmentCount = 400;

/// Default outer diameter (metres) of a new hose in a scene whose world bounds are
/// `sceneBounds`: the diagonal × kHoseDiameterPerSceneDiagonal, rounded to the nearest common
/// hose size (2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 32, 40, 50 mm; nearest by ratio) — so
/// within [kMinDefaultHoseDiameter, kMaxDefaultHoseDiameter]. An empty box, a box of zero size
/// or one with non-finite corners gives kFallbackHoseDiameter.
double defaultHoseDiameter(const Box& sceneBounds);

/// Default minimum bend radius (metres, to the centreline) of a hose of outer diameter
/// `outerDiameter` metres: kBendRadiusPerDiameter × outerDiameter.
double defaultMinBendRadius(double outerDiameter);

/// Number of axis segments of a new hose along a route `routeLength` metres long: segments of
/// at most kMaxNewSegmentLength and at most half the default bend radius (so a bend is drawn
/// with several joints), between kMinNewSegmentCount and kMaxNewSegmentCount.
int newHoseSegmentCount(double routeLength, double outerDiameter);

/// The material a new hose of outer diameter `outerDiameter` starts with, given the preset it
/// would take (the project's first preset, or a default Material when there is none).
struct NewHoseMaterial
{
    Material material;
    /// True: `preset` is used as it is (the hose refers to the preset by name); its bend radius
    /// suits the diameter. False: own values — the preset's expansion with the default minimum
    /// bend radius for the diameter.
    bool presetKept = false;
};
/// `segmentLength` (metres > 0) turns a deflection-angle limit into a bend radius
/// (bendRadiusOfTurn) to judge it; a limit of radius 0 ("no limit") does not suit any diameter.
NewHoseMaterial newHoseMaterial(const Material& preset, double outerDiameter, double segmentLength);

} // namespace chaintube::editor
