// A set of scratch vectors named by a tuple of references (std::tie of the members): cleared or
// exchanged with another set's storage at once. Internal to lib/ (the chain projection's and
// the span solver's buffers).
#pragma once

#include <cstddef>
#include <tuple>
#include <utility>
#include <vector>

namespace chaintube::detail {

/// Clears every vector of `vectors` (their capacity kept).
template <typename... Vectors> void clearEach(std::tuple<Vectors&...> vectors)
{
    std::apply([](auto&... v) { (v.clear(), ...); }, vectors);
}

/// Exchanges the storage of each vector of `a` with the one in the same place of `b`.
template <typename... Vectors>
void swapEach(std::tuple<Vectors&...> a, std::tuple<Vectors&...> b) noexcept
{
    [&]<std::size_t... I>(std::index_sequence<I...>)
    {
        (std::get<I>(a).swap(std::get<I>(b)), ...);
    }
    (std::index_sequence_for<Vectors...>{});
}

/// The size of a struct made of `count` vectors and nothing else (checks that a buffer struct's
/// tuple names all of its members).
constexpr std::size_t sizeOfVectors(std::size_t count)
{
    return count * sizeof(std::vector<double>);
}

} // namespace chaintube::detail
