// Overflow-checked unsigned/signed arithmetic for sizes, offsets and counts read from
// files: a corrupt header value must fail a check, never wrap into a small number.
#pragma once

#include <cstdint>
#include <optional>
#include <type_traits>

namespace dyncull::detail {

/// a + b, or nullopt if the sum does not fit in T.
template <class T>
std::optional<T> checkedAdd(T a, T b) {
    static_assert(std::is_integral_v<T>);
    T r{};
    if (__builtin_add_overflow(a, b, &r)) return std::nullopt;
    return r;
}

/// a * b, or nullopt if the product does not fit in T.
template <class T>
std::optional<T> checkedMul(T a, T b) {
    static_assert(std::is_integral_v<T>);
    T r{};
    if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
    return r;
}

/// Bool form for call sites that keep the result in a variable they already have:
/// `out = a + b`, false (and `out` unspecified) when the sum does not fit in T.
template <class T>
[[nodiscard]] bool checkedAdd(T a, T b, T& out) {
    static_assert(std::is_integral_v<T>);
    return !__builtin_add_overflow(a, b, &out);
}

/// `out = a * b`, like checkedAdd.
template <class T>
[[nodiscard]] bool checkedMul(T a, T b, T& out) {
    static_assert(std::is_integral_v<T>);
    return !__builtin_mul_overflow(a, b, &out);
}

/// True when bytes [offset, offset + length) lie inside a range of `size` bytes, without
/// computing offset + length (which may wrap).
constexpr bool rangeInside(std::uint64_t offset, std::uint64_t length, std::uint64_t size) {
    return offset <= size && length <= size - offset;
}

}  // namespace dyncull::detail
