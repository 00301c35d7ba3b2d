// Error values for bad input (files, parameters, NaN transforms).
// Programmer mistakes are asserts; anything a user can cause is an Error returned
// to the caller with a message that names the file or parameter and the problem.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace dyncull {

/// A human-readable failure. `message` is one line, e.g.
/// "bunny.ply: line 14: face index 40000 out of range (35947 vertices)".
struct Error {
    std::string message;
};

/// Either a value or an Error (std::expected is C++23; this is the subset we need).
/// Owns its value; moving out with `take()` leaves it empty.
template <class T>
class Expected {
public:
    Expected(T value) : v_(std::move(value)) {}          // NOLINT: implicit by design
    Expected(Error error) : v_(std::move(error)) {}      // NOLINT: implicit by design

    bool ok() const { return std::holds_alternative<T>(v_); }
    explicit operator bool() const { return ok(); }

    const Error& error() const { assert(!ok()); return std::get<Error>(v_); }
    T& value() { assert(ok()); return std::get<T>(v_); }
    const T& value() const { assert(ok()); return std::get<T>(v_); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() { return value(); }
    T take() { assert(ok()); return std::move(std::get<T>(v_)); }

private:
    std::variant<T, Error> v_;
};

/// Success-or-error for operations without a result value.
class Status {
public:
    Status() = default;
    Status(Error error) : error_(std::move(error.message)), failed_(true) {}  // NOLINT
    bool ok() const { return !failed_; }
    explicit operator bool() const { return ok(); }
    const std::string& message() const { return error_; }

private:
    std::string error_;
    bool failed_ = false;
};

}  // namespace dyncull
