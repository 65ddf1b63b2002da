#include "chaintube/material.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

namespace chaintube {

namespace {

std::string describe(double value)
{
    std::ostringstream out;
    out.precision(17);
    out << value;
    return out.str();
}
} // namespace

BendLimit BendLimit::deflectionAngle(double radians)
{
    if (!std::isfinite(radians) || radians < 0.0 || radians >= std::numbers::pi)
        throw InvalidArgument("bendLimit.deflectionAngle: expected radians in [0, pi), got " +
                              describe(radians));
    return {Kind::DeflectionAngle, radians};
}

BendLimit BendLimit::minBendRadius(double metres)
{
    if (!std::isfinite(metres) || metres < 0.0)
        throw InvalidArgument("bendLimit.minBendRadius: expected metres >= 0, got " +
                              describe(metres));
    return {Kind::MinBendRadius, metres};
}

void Material::validate() const
{
    if (!std::isfinite(expansionCoefficient) || expansionCoefficient < 0.0 ||
        expansionCoefficient >= 1.0)
        throw InvalidArgument("material.expansionCoefficient: expected a number in [0, 1), got " +
                              describe(expansionCoefficient));
    if (bendLimit.kind == BendLimit::Kind::DeflectionAngle)
        static_cast<void>(BendLimit::deflectionAngle(bendLimit.value));
    else
        static_cast<void>(BendLimit::minBendRadius(bendLimit.value));
}

double jointDeflectionLimit(const BendLimit& limit, double segmentLength)
{
    if (limit.kind == BendLimit::Kind::DeflectionAngle) return limit.value;
    if (limit.value <= 0.0) return std::numbers::pi;
    const double half = segmentLength / (2.0 * limit.value);
    if (half >= 1.0) return std::numbers::pi;
    return 2.0 * std::asin(half);
}

double bendRadiusOfTurn(double segmentLength, double turnRadians)
{
    const double s = std::sin(0.5 * turnRadians);
    if (s <= 0.0) return std::numeric_limits<double>::max();
    const double r = segmentLength / (2.0 * s);
    return std::isfinite(r) ? r : std::numeric_limits<double>::max();
}

} // namespace chaintube
