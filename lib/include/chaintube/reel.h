// ChainTube — reeling a hose in and paying it out at runtime (a hose drum, a cable winch).
#pragma once

#include "chaintube/hose.h"

#include <string>

namespace chaintube {

/// Which end of a hose: point 0 or the last point.
enum class HoseEnd {
    Start, ///< point 0
    End    ///< point pointCount() − 1
};

const char* toString(HoseEnd end);

/// How far a reel step may move a point that was there before it, as a multiple of the length
/// the step pays: a step that would move one farther is undone (Clamped). More than 1 because a
/// bent hose cannot always keep to |paid| (lib/README.md, "Reel in, pay out").
constexpr double kReelMoveFactor = 2.0;

/// What a reel call did. Always look at status.
struct [[nodiscard]] ReelResult
{
    /// Ok: the length asked for was paid. Clamped: less was paid (`clamped` says so): a length
    /// bound was reached, the last segment beyond the outlet is at half its rest length, a
    /// straight taut span could take or give no more, or a step would have moved a point more
    /// than kReelMoveFactor × its length (`message` says which). InvalidInput: nothing changed
    /// (`message` names the argument).
    Status status = Status::Ok;
    /// Rest length paid out (> 0) or reeled in (< 0) by this call, metres. The hose's
    /// restLengthTotal() changed by exactly this.
    double paid = 0.0;
    bool clamped = false;
    int segmentsAdded = 0;   ///< points inserted next to the outlet
    int segmentsRemoved = 0; ///< points removed next to the outlet
    /// Sum over the call's steps of the largest distance (metres) a point moved in the step: a
    /// bound on how far any point that was there before the call moved. At most kReelMoveFactor
    /// × |paid|; exactly |paid| where the hose beyond the outlet moved rigidly.
    double largestMove = 0.0;
    /// The constraint state after the call (Hose::measureViolation) and the span solver's
    /// Newton steps in `iterations`.
    UpdateResult update;
    /// Empty when Ok; otherwise what was clamped or rejected.
    std::string message;
    bool ok() const { return status == Status::Ok; }
};

/// Pays out (`length` > 0, metres) or reels in (`length` < 0) hose at `end`, where the hose
/// leaves a reel: the attachment that fixes that end point is the reel's outlet (its points stay
/// fixed to its frame), and the length changes in the segment that leaves it, the one between
/// the attachment's last point and the first free point. A frame's call is speed × frame time.
///
/// The total rest length stays within [minLength, maxLength] (metres, 0 ≤ minLength ≤
/// maxLength; maxLength may be +inf): `length` is clamped so that the total gets no nearer
/// than 0 to a bound, and a hose already outside them moves only towards them. The reel
/// segment keeps the hose's segment rest length l (its outer neighbour's; with none, the
/// longest other segment's, else HoseSpec::segmentLength): beyond 1.5 l it is
/// split (a point inserted on it, l from its outer point), reeling in below 0.5 l it is merged
/// with its outer neighbour (the point between removed, see below), so the new length appears at
/// the outlet and nothing else is rescaled. The reel segment's outer point moves along it by the
/// length paid. A free tail beyond it (nothing fixed or held up to the hose's end) moves with it
/// rigidly, so every other length and bend stays as it is and no point moves more than |paid|,
/// unless a joint's limit tightened with the reel segment's rest length (a limit from a minimum
/// bend radius): then, and after a merge, the tail follows the reel segment's outer point by the
/// paper's pass, each point drawn towards the one before it, so a bend beyond the outlet
/// straightens as it comes in. A span to a pinned point beyond is closed by the span solver, its
/// sag deepening or flattening with the length (a straight taut span cannot take more length and
/// cannot give any: Clamped). Reeling in, the reel segment merges once it is no longer than the
/// step draws in, or sooner where the merged segment's far point moves no more than that: that
/// point is placed at the merged rest length from the outlet, along its chord, within |paid| of
/// where it was. No step moves a point by more than kReelMoveFactor × the length it pays (a
/// joint on its limit and a span's shape need more than |paid|: lib/README.md). A call is done
/// in steps of at most 0.5 l (at most 64); a step that would leave a constraint violated or move
/// a point farther than that is undone (Clamped).
/// After every call every segment is in its band and every joint within its limit when they
/// were before. Colliders are not consulted (the
/// next update resolves contacts); the held point stays held (released if it is the point a
/// merge removes); gravity velocities and the grab's carried state start again.
///
/// Decided cases (each an InvalidInput with a message, the hose unchanged): a non-finite
/// length or bound, minLength < 0, minLength > maxLength; an end that no attachment fixes (a
/// free end is not on a reel); an outlet with no free point beyond it. `length` 0 is Ok and does
/// nothing. The last segment beyond the outlet (the hose's end, or two points left) never
/// shrinks below 0.5 l: reeling in further is Clamped.
ReelResult reel(Hose& hose, HoseEnd end, double length, double minLength, double maxLength);

/// As reel(), with clip `clipId` (Hose::addClip) as the reel's outlet and the drum towards
/// `drumEnd`: the hose between the clip and `drumEnd` stands for the hose on the drum and keeps
/// its shape and length; the length changes in the segment that leaves the clip's held segment
/// on the other side. A clip's slide and end stops (rest arc lengths from point 0) move with
/// the length paid before them. An unknown id or an id of a fixed attachment: InvalidInput.
ReelResult reelThroughClip(Hose& hose, int clipId, HoseEnd drumEnd, double length, double minLength,
                           double maxLength);

} // namespace chaintube
