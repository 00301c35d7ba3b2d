// Structure-aware mutations shared by the text-format fuzz targets (issue 19). libFuzzer's
// byte-level mutations practically never turn "96" into "18446744073709551615", yet such
// numbers are what break a loader's size arithmetic (offset + length wrapping past 2^64),
// and they never nest brackets 15,000 deep. These helpers find the decimal numbers in a
// text input and replace some of them with boundary values, or wrap one in deep brackets;
// each target's LLVMFuzzerCustomMutator (mutateText) uses them with some probability and
// otherwise falls back to LLVMFuzzerMutate, which still applies the -dict tokens.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <random>
#include <string>
#include <string_view>
#include <vector>

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t maxSize);

namespace dyncull::fuzz {

struct NumberSpan {
    std::size_t begin = 0, end = 0;
};

inline bool isDigit(std::uint8_t c) { return c >= '0' && c <= '9'; }

/// Every decimal number in `data` ([-]digits[.digits][e[+-]digits]): JSON numbers, PLY
/// header counts, OBJ indices (each part of "1/2/3" separately).
inline std::vector<NumberSpan> findNumbers(const std::uint8_t* data, std::size_t size) {
    std::vector<NumberSpan> out;
    std::size_t i = 0;
    while (i < size) {
        if (!isDigit(data[i])) {
            ++i;
            continue;
        }
        const std::size_t begin = i > 0 && data[i - 1] == '-' ? i - 1 : i;
        while (i < size && isDigit(data[i])) ++i;
        if (i + 1 < size && data[i] == '.' && isDigit(data[i + 1]))
            for (++i; i < size && isDigit(data[i]); ++i) {}
        if (i < size && (data[i] == 'e' || data[i] == 'E')) {
            std::size_t j = i + 1;
            if (j < size && (data[j] == '+' || data[j] == '-')) ++j;
            if (j < size && isDigit(data[j]))
                for (i = j; i < size && isDigit(data[i]); ++i) {}
        }
        out.push_back({begin, i});
    }
    return out;
}

/// The integer part of a number's text, saturated at 2^64 - 1 (the sign is ignored).
inline std::uint64_t integerValue(std::string_view text) {
    std::uint64_t v = 0;
    for (char c : text) {
        if (c == '-') continue;
        if (!isDigit(static_cast<std::uint8_t>(c))) break;
        const std::uint64_t d = static_cast<std::uint64_t>(c - '0');
        if (v > (UINT64_MAX - d) / 10) return UINT64_MAX;
        v = v * 10 + d;
    }
    return v;
}

/// A boundary value to put in place of `current`; `other` is another number of the same
/// input, so that "2^64 - other" makes current + other wrap to (nearly) zero, which is the
/// shape of an `offset + length > size` check that overflows.
inline std::string boundaryNumber(std::string_view current, std::string_view other, std::minstd_rand& rng) {
    // Integer limits of every width a loader might store a count or offset in, the same
    // written as floats, and the non-finite spellings strtod / JSON parsers may accept.
    static constexpr const char* kFixed[] = {
        "0", "1", "-1", "2", "3", "4", "255", "256", "65535", "65536", "2147483647", "2147483648",
        "-2147483648", "-2147483649", "4294967295", "4294967296", "9007199254740992", "9007199254740993",
        "9223372036854775807", "9223372036854775808", "-9223372036854775808", "18446744073709551615",
        "18446744073709551616", "18446744073709551614", "1e19", "1e308", "-1e308", "1e309", "-0", "0.5",
        "1e-320", "NaN", "nan", "-nan", "inf", "-inf", "Infinity"};
    const std::uint64_t v = integerValue(current), w = integerValue(other);
    const std::uint64_t delta = rng() % 4 == 0 ? rng() % 17 : 0;  // usually exact, sometimes near
    switch (rng() % 4) {
        case 0: return kFixed[rng() % std::size(kFixed)];
        case 1: {  // 2^k, 2^k - 1, 2^64 - 2^k
            const std::uint64_t p = std::uint64_t{1} << (rng() % 64);
            switch (rng() % 3) {
                case 0: return std::to_string(p);
                case 1: return std::to_string(p - 1);
                default: return std::to_string(~p + 1);
            }
        }
        case 2: {  // wrap partners: 2^W - other (- delta) for W = 64, 63, 32, 31
            static constexpr int kWidths[] = {64, 63, 32, 31};
            const int width = kWidths[rng() % 4];
            const std::uint64_t limit = width == 64 ? 0 : std::uint64_t{1} << width;  // 2^64 wraps to 0
            return std::to_string(limit - w - delta);
        }
        default:  // the current value nudged, or its 2^64 complement
            switch (rng() % 4) {
                case 0: return std::to_string(v + 1 + delta);
                case 1: return std::to_string(v - 1 - delta);
                case 2: return std::to_string(v * 2);
                default: return std::to_string(~v + 1 - delta);
            }
    }
}

/// Replaces 1-3 numbers of `data` with boundary values. Returns the new size, or 0 when the
/// input has no number or the result would exceed `maxSize`.
inline std::size_t mutateNumbers(std::uint8_t* data, std::size_t size, std::size_t maxSize, std::minstd_rand& rng) {
    const std::vector<NumberSpan> numbers = findNumbers(data, size);
    if (numbers.empty()) return 0;
    std::string text(reinterpret_cast<const char*>(data), size);
    const unsigned replacements = 1 + static_cast<unsigned>(rng() % 4 == 0 ? 1 + rng() % 2 : 0);
    // Pick distinct spans and replace from the back so earlier offsets stay valid.
    std::vector<std::size_t> picks;
    for (unsigned r = 0; r < replacements; ++r) picks.push_back(rng() % numbers.size());
    std::sort(picks.begin(), picks.end());
    picks.erase(std::unique(picks.begin(), picks.end()), picks.end());
    for (auto it = picks.rbegin(); it != picks.rend(); ++it) {
        const NumberSpan s = numbers[*it];
        const NumberSpan o = numbers[rng() % numbers.size()];
        const std::string_view cur(text.data() + s.begin, s.end - s.begin);
        const std::string value =
            boundaryNumber(cur, std::string_view(reinterpret_cast<const char*>(data) + o.begin, o.end - o.begin), rng);
        text.replace(s.begin, s.end - s.begin, value);
    }
    if (text.size() > maxSize) return 0;
    std::memcpy(data, text.data(), text.size());
    return text.size();
}

/// Wraps one number of `data` in N levels of "[" ... "]" (JSON stays valid), N up to what
/// `maxSize` allows: deep nesting is what overflows a recursive parser's stack.
inline std::size_t mutateNesting(std::uint8_t* data, std::size_t size, std::size_t maxSize, std::minstd_rand& rng) {
    const std::vector<NumberSpan> numbers = findNumbers(data, size);
    if (numbers.empty() || maxSize <= size + 2) return 0;
    const std::size_t room = (maxSize - size) / 2;
    // Mostly as deep as fits; sometimes shallower so moderate depths are covered too.
    const std::size_t depth = rng() % 2 ? room : 1 + rng() % room;
    const NumberSpan s = numbers[rng() % numbers.size()];
    std::string text(reinterpret_cast<const char*>(data), size);
    text.insert(s.end, depth, ']');
    text.insert(s.begin, depth, '[');
    std::memcpy(data, text.data(), text.size());
    return text.size();
}

/// The binary-format counterpart of mutateNumbers: overwrites a 4- or 8-byte aligned word at
/// or after `begin` (past a header the harness rewrites anyway) with a boundary value, in
/// place. libFuzzer's own integer mutation adds small deltas; counts and offsets read from
/// a binary file break at the extremes. Returns 0 when there is no such word.
inline std::size_t mutateBinaryWord(std::uint8_t* data, std::size_t size, std::size_t begin, std::minstd_rand& rng) {
    static constexpr std::uint64_t kValues[] = {0, 1, 0x7F, 0x80, 0xFF, 0xFFFF, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF,
                                                0x100000000, 0x7FFFFFFFFFFFFFFF, 0x8000000000000000,
                                                0xFFFFFFFFFFFFFFFF, 0x7FC00000 /* float NaN */,
                                                0x7F800000 /* float inf */, 0x7FF8000000000000 /* double NaN */};
    const std::size_t width = rng() % 2 ? 4 : 8;
    if (size < begin + width) return 0;
    const std::size_t slots = (size - begin - width) / 4 + 1;
    const std::size_t at = begin + rng() % slots * 4;
    std::uint64_t v = kValues[rng() % std::size(kValues)];
    if (rng() % 4 == 0) v -= rng() % 16;  // near the boundary, below it
    std::memcpy(data + at, &v, width);  // little-endian host: the low bytes first
    return size;
}

/// DYNCULL_FUZZ_PLAIN=1 reduces the custom mutators to LLVMFuzzerMutate: the byte-level
/// baseline that structure-aware fuzzing is measured against (scripts/fuzz_rediscover.sh).
inline bool plainMutation() {
    static const bool plain = [] {
        const char* v = std::getenv("DYNCULL_FUZZ_PLAIN");
        return v && std::string_view(v) == "1";
    }();
    return plain;
}

/// DYNCULL_FUZZ_NO_NESTING=1 turns the nesting mutation off, so that a run looks for the
/// other bug classes once deep nesting is known (scripts/fuzz_rediscover.sh --no-nesting).
inline bool nestingOff() {
    static const bool off = [] {
        const char* v = std::getenv("DYNCULL_FUZZ_NO_NESTING");
        return v && std::string_view(v) == "1";
    }();
    return off;
}

/// The custom mutation for a text format: boundary numbers with probability 1/3, deep
/// nesting (when `nest`) 1/64, else libFuzzer's own mutation (dictionary included).
inline std::size_t mutateText(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed, bool nest) {
    if (plainMutation()) return LLVMFuzzerMutate(data, size, maxSize);
    nest = nest && !nestingOff();
    std::minstd_rand rng(seed);
    const unsigned dice = static_cast<unsigned>(rng() % 192);
    std::size_t n = 0;
    if (nest && dice < 3) n = mutateNesting(data, size, maxSize, rng);
    else if (dice < 64) n = mutateNumbers(data, size, maxSize, rng);
    return n ? n : LLVMFuzzerMutate(data, size, maxSize);
}

/// The custom mutation for a binary format whose first `header` bytes the harness
/// rewrites: a boundary word in the payload with probability 1/4, else LLVMFuzzerMutate.
inline std::size_t mutateBinary(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed,
                                std::size_t header) {
    if (plainMutation()) return LLVMFuzzerMutate(data, size, maxSize);
    std::minstd_rand rng(seed);
    const std::size_t n = rng() % 4 == 0 ? mutateBinaryWord(data, size, header, rng) : 0;
    return n ? n : LLVMFuzzerMutate(data, size, maxSize);
}

}  // namespace dyncull::fuzz
