#pragma once
// Errors of the swish embedding API, as exceptions or as values.
//
// Every throwing call of the API throws swish::api::Error (derived from std::runtime_error) and
// nothing else; what() names the object (file, model, batch) and what is wrong with it, and code()
// says which kind of failure it was so that a host can react without parsing text. The calls a host
// typically wants to handle without exceptions (creating a runtime, loading a model) also come as
// try* functions returning Result<T>, which holds either the value or the Error.
//
// After an Error nothing is half-done: a failed create/load leaves nothing allocated, a failed
// recordFrame recorded nothing into the command buffer and changed no frame state.
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace swish::api {

enum class ErrorCode {
  InvalidArgument,    // a call's arguments do not fit (sizes, indices, a null handle, non-finite data)
  BadModel,           // a model file that cannot be read, or fails its checks (the message names the section)
  DeviceUnsupported,  // no Vulkan, no usable device, or a device lacking a feature swish needs
  FrameInFlight,      // recording into frame resources the GPU may still read (frame not retired)
  VulkanFailure,      // an unexpected VkResult (out of memory, device lost): the call, file and line
  Internal,           // anything else; a bug worth reporting
};

const char* errorCodeName(ErrorCode code);

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& what) : std::runtime_error(what), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

// Either a T or the Error that prevented it. value() throws the Error when there is none.
template <class T>
class Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(implicit)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(implicit)
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & {
    if (!ok()) throw std::get<1>(v_);
    return std::get<0>(v_);
  }
  T&& value() && {
    if (!ok()) throw std::get<1>(v_);
    return std::get<0>(std::move(v_));
  }
  const Error& error() const { return std::get<1>(v_); }  // only when !ok()

 private:
  std::variant<T, Error> v_;
};

}  // namespace swish::api
