// Error values for bad input (files, parameters, NaN transforms) and for the GL context.
// Programmer mistakes are asserts; anything a user can cause is an Error returned
// to the caller with a message that names the file or parameter and the problem, and a
// code a program can branch on.
#pragma once

#include <cassert>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <variant>

namespace dyncull {

/// What kind of failure an Error is, for code that must react differently (retry, recreate
/// the context, report to the user). The message says the rest.
enum class ErrorCode : std::uint8_t {
    BadArgument,   ///< a parameter, transform, camera, handle or mesh the caller passed is invalid
    BadFile,       ///< a file is missing, unreadable, truncated or malformed
    OutOfMemory,   ///< the GPU (GL_OUT_OF_MEMORY) or a size limit refused an allocation
    ContextLost,   ///< the GL context was reset; recreate it and everything made on it
    WrongContext,  ///< the GL context current on this thread is not the one the object was made on (or none is)
    GlError,       ///< a GL error was raised inside a dyncull call (by dyncull or by a callback it ran)
    Unsupported,   ///< the driver lacks a feature dyncull needs, or a framebuffer it cannot use
    Io,            ///< writing a file failed (disk full, permissions)
};

/// A short lowercase name of the code, e.g. "wrong context".
const char* errorCodeName(ErrorCode code);

/// A human-readable failure. `message` is one line, e.g.
/// "bunny.ply: line 14: face index 40000 out of range (35947 vertices)".
struct Error {
    std::string message;
    ErrorCode code = ErrorCode::BadArgument;
};

namespace detail {
/// A programmer mistake (reading the value of a failed Expected): say which error was
/// ignored, then abort, in every build type (an assert would vanish under NDEBUG and
/// std::get would throw bad_variant_access far from the cause).
[[noreturn]] inline void valueOfFailedExpected(const Error& e) {
    std::fprintf(stderr, "dyncull: the value of a failed Expected was read; its error was: %s\n", e.message.c_str());
    std::abort();
}
}  // namespace detail

/// Either a value or an Error (std::expected is C++23; this is the subset we need).
/// Owns its value; moving out with `take()` leaves it empty. Reading the value of an
/// Expected that holds an error aborts with the error's message.
template <class T>
class [[nodiscard]] Expected {
public:
    Expected(T value) : v_(std::move(value)) {}          // NOLINT: implicit by design
    Expected(Error error) : v_(std::move(error)) {}      // NOLINT: implicit by design

    bool ok() const { return std::holds_alternative<T>(v_); }
    explicit operator bool() const { return ok(); }

    const Error& error() const { assert(!ok()); return std::get<Error>(v_); }
    T& value() { check(); return std::get<T>(v_); }
    const T& value() const { check(); return std::get<T>(v_); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() { return value(); }
    T take() { check(); return std::move(std::get<T>(v_)); }

private:
    void check() const {
        if (!ok()) detail::valueOfFailedExpected(std::get<Error>(v_));
    }
    std::variant<T, Error> v_;
};

/// Success-or-error for operations without a result value.
class [[nodiscard]] Status {
public:
    Status() = default;
    Status(Error error) : error_(std::move(error.message)), code_(error.code), failed_(true) {}  // NOLINT
    bool ok() const { return !failed_; }
    explicit operator bool() const { return ok(); }
    const std::string& message() const { return error_; }
    /// Meaningful only when !ok().
    ErrorCode code() const { return code_; }
    /// The failure as an Error (message and code), to pass up as another call's result.
    Error error() const { assert(failed_); return Error{error_, code_}; }

private:
    std::string error_;
    ErrorCode code_ = ErrorCode::BadArgument;
    bool failed_ = false;
};

inline const char* errorCodeName(ErrorCode code) {
    switch (code) {
        case ErrorCode::BadArgument: return "bad argument";
        case ErrorCode::BadFile: return "bad file";
        case ErrorCode::OutOfMemory: return "out of memory";
        case ErrorCode::ContextLost: return "context lost";
        case ErrorCode::WrongContext: return "wrong context";
        case ErrorCode::GlError: return "GL error";
        case ErrorCode::Unsupported: return "unsupported";
        case ErrorCode::Io: return "I/O";
    }
    return "unknown";
}

}  // namespace dyncull
