// The banded LDLᵀ solves of lib/src/banded_ldlt.h: the twisted solve (both ends at once) against
// the sequential one, its fallback, and rows dropped in either half and in the separator.
#include "banded_ldlt.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace {

using chaintube::detail::resolveBandedLdltTwisted;
using chaintube::detail::solveBandedLdlt;
using chaintube::detail::solveBandedLdltTwisted;

/// A symmetric m × m matrix of half-bandwidth width − 1 as G Gᵀ (row i of G spans columns i …
/// i + width − 1, so A is positive semi-definite), stored as solveBandedLdlt takes it.
struct Band
{
    size_t m = 0, width = 0;
    std::vector<double> upper; ///< upper[i · width + d] = A(i, i + d)

    double at(size_t i, size_t j) const
    {
        if (j < i) std::swap(i, j);
        return j - i < width ? upper[i * width + (j - i)] : 0.0;
    }
    /// A x
    std::vector<double> times(const std::vector<double>& x) const
    {
        std::vector<double> y(m, 0.0);
        for (size_t i = 0; i < m; ++i)
            for (size_t j = i >= width ? i - width + 1 : 0; j < m && j < i + width; ++j)
                y[i] += at(i, j) * x[j];
        return y;
    }
};

/// G's rows in `zeroRows` are zero: A's rows and columns there are exactly zero.
Band randomBand(size_t m, size_t width, unsigned seed, const std::vector<size_t>& zeroRows = {})
{
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> uniform(0.5, 1.5);
    const size_t columns = m + width - 1;
    std::vector<double> g(m * columns, 0.0);
    for (size_t i = 0; i < m; ++i) {
        if (std::find(zeroRows.begin(), zeroRows.end(), i) != zeroRows.end()) continue;
        for (size_t c = i; c < i + width; ++c)
            g[i * columns + c] = (c == i ? 2.0 : 0.5) * uniform(random);
    }
    Band band;
    band.m = m;
    band.width = width;
    band.upper.assign(m * width, 0.0);
    for (size_t i = 0; i < m; ++i)
        for (size_t d = 0; d < width && i + d < m; ++d) {
            double sum = 0.0;
            for (size_t c = 0; c < columns; ++c)
                sum += g[i * columns + c] * g[(i + d) * columns + c];
            band.upper[i * width + d] = sum;
        }
    return band;
}

/// Largest |A x − b| relative to the largest |b|.
double residual(const Band& band, const std::vector<double>& x, const std::vector<double>& b)
{
    const std::vector<double> ax = band.times(x);
    double worst = 0.0, scale = 0.0;
    for (size_t i = 0; i < band.m; ++i) {
        worst = std::max(worst, std::abs(ax[i] - b[i]));
        scale = std::max(scale, std::abs(b[i]));
    }
    return worst / scale;
}

std::vector<double> randomVector(size_t m, unsigned seed)
{
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    std::vector<double> v(m);
    for (double& x : v)
        x = uniform(random);
    return v;
}

TEST(BandedLdlt, TheTwistedSolveSolvesWhatTheSequentialOneSolves)
{
    int compared = 0;
    for (size_t width : {2, 3, 5, 7, 9})
        for (size_t m :
             {4 * width, 4 * width + 1, 4 * width + 2, size_t(45), size_t(155), size_t(400)}) {
            const Band band = randomBand(m, width, static_cast<unsigned>(7 * m + width));
            const std::vector<double> b = randomVector(m, static_cast<unsigned>(m + width));
            std::vector<double> sequential = b, twisted = b;
            std::vector<double> factor = band.upper;
            EXPECT_EQ(solveBandedLdlt(factor.data(), sequential.data(), m, width), 0u);
            factor = band.upper;
            EXPECT_EQ(solveBandedLdltTwisted(factor.data(), twisted.data(), m, width), 0u);
            EXPECT_LT(residual(band, twisted, b), 1e-13) << "m " << m << ", width " << width;
            for (size_t i = 0; i < m; ++i)
                EXPECT_NEAR(twisted[i], sequential[i], 1e-12 * (1.0 + std::abs(sequential[i])))
                    << "m " << m << ", width " << width << ", row " << i;
            ++compared;
        }
    EXPECT_EQ(compared, 30);
}

TEST(BandedLdlt, FewerThanFourWidthsOfRowsAreSolvedSequentiallyBitForBit)
{
    for (size_t width : {1, 2, 5})
        for (size_t m = 1; m < 4 * width; ++m) {
            const Band band = randomBand(m, width, static_cast<unsigned>(m));
            const std::vector<double> b = randomVector(m, static_cast<unsigned>(m + 1));
            std::vector<double> sequential = b, twisted = b;
            std::vector<double> factor = band.upper;
            solveBandedLdlt(factor.data(), sequential.data(), m, width);
            factor = band.upper;
            solveBandedLdltTwisted(factor.data(), twisted.data(), m, width);
            EXPECT_EQ(std::memcmp(sequential.data(), twisted.data(), m * sizeof(double)), 0)
                << "m " << m << ", width " << width;
        }
}

TEST(BandedLdlt, AZeroRowIsDroppedInEitherHalfAndInTheSeparator)
{
    // 155 rows of width 5: the top half is rows 0 … 74, the separator 75 … 78, the bottom half
    // 79 … 154 (solveBandedLdltTwisted). A zero row anywhere: one row dropped, x = 0 there, the
    // other equations hold.
    const size_t m = 155, width = 5;
    for (size_t zero : {size_t(0), size_t(40), size_t(74), size_t(75), size_t(77), size_t(78),
                        size_t(79), size_t(120), size_t(154)}) {
        const Band band = randomBand(m, width, 11, {zero});
        // A consistent right-hand side: b = A y.
        const std::vector<double> b = band.times(randomVector(m, 13));
        ASSERT_EQ(b[zero], 0.0);
        for (const bool twistedOrder : {false, true}) {
            std::vector<double> factor = band.upper, x = b;
            const size_t dropped = twistedOrder
                                       ? solveBandedLdltTwisted(factor.data(), x.data(), m, width)
                                       : solveBandedLdlt(factor.data(), x.data(), m, width);
            EXPECT_EQ(dropped, 1u) << "zero row " << zero << (twistedOrder ? ", twisted" : "");
            EXPECT_EQ(x[zero], 0.0) << "zero row " << zero;
            EXPECT_LT(residual(band, x, b), 1e-12)
                << "zero row " << zero << (twistedOrder ? ", twisted" : "");
            for (double v : x)
                EXPECT_TRUE(std::isfinite(v));
        }
    }
}

/// `band` with the rows and columns outside `kept` decoupled (unit diagonal, no coupling), as
/// the chain projection leaves rows outside its working set; `rhs` 0 there.
struct Masked
{
    std::vector<double> upper, rhs;
};
Masked masked(const Band& band, const std::vector<double>& b, const std::vector<char>& kept)
{
    Masked out{band.upper, b};
    for (size_t i = 0; i < band.m; ++i)
        for (size_t d = 0; d < band.width; ++d) {
            const bool both = kept[i] && (i + d >= band.m || kept[i + d]);
            if (!both) out.upper[i * band.width + d] = d == 0 ? 1.0 : 0.0;
        }
    for (size_t i = 0; i < band.m; ++i)
        if (!kept[i]) out.rhs[i] = 0.0;
    return out;
}

TEST(BandedLdlt, RefactoringFromTheChangedRowsGivesTheFullSolveBitForBit)
{
    // Rows leave and join (in the top half, the separator, the bottom half, far apart), some of
    // A's rows zero (dropped): the factor of the first set updated for the second gives the
    // factor and the solution of the second set's full solve, bit for bit.
    int compared = 0;
    for (size_t width : {1, 2, 3, 5, 7})
        for (size_t m : {size_t(3), 4 * width + 1, size_t(45), size_t(155)}) {
            for (unsigned trial = 0; trial < 12; ++trial) {
                const unsigned seed = static_cast<unsigned>(1000 * m + 10 * width + trial);
                std::mt19937 random(seed);
                const std::vector<size_t> zeroRows =
                    trial % 3 == 0 ? std::vector<size_t>{random() % m} : std::vector<size_t>{};
                const Band band = randomBand(m, width, seed, zeroRows);
                const std::vector<double> b = randomVector(m, seed + 1);
                std::vector<char> before(m), after(m);
                for (size_t i = 0; i < m; ++i)
                    before[i] = random() % 4 != 0;
                after = before;
                size_t first = m, last = 0;
                const int changes = 1 + static_cast<int>(random() % 3);
                for (int c = 0; c < changes; ++c) {
                    const size_t r = random() % m;
                    after[r] = !after[r];
                    first = std::min(first, r);
                    last = std::max(last, r);
                }
                const Masked a = masked(band, b, before), c = masked(band, b, after);
                std::vector<double> factor = a.upper, x = a.rhs;
                solveBandedLdltTwisted(factor.data(), x.data(), m, width);
                std::vector<double> fullFactor = c.upper, full = c.rhs;
                const size_t fullDropped =
                    solveBandedLdltTwisted(fullFactor.data(), full.data(), m, width);
                std::vector<unsigned char> keep(after.begin(), after.end());
                const size_t dropped =
                    resolveBandedLdltTwisted(factor.data(), x.data(), m, width, first, last,
                                             band.upper.data(), b.data(), keep.data());
                EXPECT_EQ(dropped, fullDropped) << "m " << m << ", width " << width;
                EXPECT_EQ(std::memcmp(x.data(), full.data(), m * sizeof(double)), 0)
                    << "m " << m << ", width " << width << ", rows " << first << " … " << last;
                for (size_t i = 0; i < m; ++i)
                    for (size_t d = 0; d < width && i + d < m; ++d)
                        ASSERT_EQ(factor[i * width + d], fullFactor[i * width + d])
                            << "m " << m << ", width " << width << ", entry " << i << ", " << d;
                ++compared;
            }
        }
    EXPECT_EQ(compared, 5 * 4 * 12);
}

} // namespace
