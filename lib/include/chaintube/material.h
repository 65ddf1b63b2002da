// ChainTube — hose material: stretch band and bend limit.
#pragma once

#include "chaintube/types.h"

#include <string>

namespace chaintube {

/// The bending limit of a hose, in one of two equivalent forms.
///
/// * DeflectionAngle — the paper's parameter: the angle (radians) by which two neighbouring
///   axis segments may deviate from a straight line, the same at every joint. The hose then
///   gets more flexible as the axis is refined: a polyline with segment length l and turn θ
///   has bend radius R = l / (2·sin(θ/2)).
/// * MinBendRadius — a hose datasheet's minimum bend radius (metres, measured to the
///   centreline). The per-joint angle is derived from each joint's actual rest segment length
///   l as θ = 2·asin(l / (2R)), so the hose bends the same at any axis resolution. When
///   l ≥ 2R a single segment is longer than the bend diameter and the joint is unlimited (π).
struct BendLimit
{
    enum class Kind { DeflectionAngle, MinBendRadius };
    Kind kind = Kind::MinBendRadius;
    double value = 0.05; ///< radians for DeflectionAngle, metres for MinBendRadius

    /// Throws InvalidArgument unless 0 ≤ radians < π and finite.
    static BendLimit deflectionAngle(double radians);
    /// Throws InvalidArgument unless radius ≥ 0 and finite (0 means "no limit").
    static BendLimit minBendRadius(double metres);

    bool operator==(const BendLimit& o) const { return kind == o.kind && value == o.value; }
};

/// Material parameters of one hose.
struct Material
{
    /// Allowed relative change of every axis segment's length: each segment stays within
    /// [L0·(1−e), L0·(1+e)] of its rest length L0. Range [0, 1); the paper uses 0–0.4.
    double expansionCoefficient = 0.05;
    BendLimit bendLimit;

    /// Throws InvalidArgument naming the field if a value is outside its range.
    void validate() const;
    bool operator==(const Material& o) const
    {
        return expansionCoefficient == o.expansionCoefficient && bendLimit == o.bendLimit;
    }
};

/// Per-joint deflection limit (radians, in [0, π]) for a joint whose adjacent rest segments
/// have mean length segmentLength (metres > 0). See BendLimit.
double jointDeflectionLimit(const BendLimit& limit, double segmentLength);

/// Bend radius (metres) of a polyline with segment length l turning by θ at each joint:
/// l / (2·sin(θ/2)); +infinity is never returned: θ ≤ 1e-300 gives the largest finite double.
double bendRadiusOfTurn(double segmentLength, double turnRadians);

} // namespace chaintube
