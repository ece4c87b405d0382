#pragma once
// One error type for the whole library. Expected failures (bad file, no device, missing feature)
// carry a message a person can act on: which file or object, and what is wrong with it.
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace swish {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

// Result of an operation that can fail in an expected way, for APIs that prefer values to exceptions.
template <class T>
class Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}      // NOLINT(implicit)
  Expected(Error error) : v_(std::move(error)) {}  // NOLINT(implicit)
  bool ok() const { return std::holds_alternative<T>(v_); }
  explicit operator bool() const { return ok(); }
  T& value() {
    if (!ok()) throw std::get<Error>(v_);
    return std::get<T>(v_);
  }
  const T& value() const {
    if (!ok()) throw std::get<Error>(v_);
    return std::get<T>(v_);
  }
  T* operator->() { return &value(); }
  T& operator*() { return value(); }
  const Error& error() const { return std::get<Error>(v_); }

 private:
  std::variant<T, Error> v_;
};

}  // namespace swish
