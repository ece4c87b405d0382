#pragma once
// Private state behind the public handles of include/swish/api_runtime.hpp, and the translation of
// internal errors (swish::Error) into the public swish::api::Error with a code.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swish/api_runtime.hpp"
#include "swish/core/error.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/model/model.hpp"
#include "swish/runtime/frame_evaluator.hpp"
#include "swish/runtime/level_planner.hpp"
#include "swish/runtime/quality_levels.hpp"

namespace swish::api {

struct RuntimeImpl {
  explicit RuntimeImpl(gpu::Context c) : ctx(std::move(c)) {}
  gpu::Context ctx;  // at a stable address: GPU objects keep pointers to it
};

struct ModelImpl {
  std::shared_ptr<RuntimeImpl> runtime;
  swish::Model model;
  std::unique_ptr<gpu::GpuModel> gpuModel;
  ModelInfo info;
};

struct BatchImpl {
  std::shared_ptr<ModelImpl> model;
  std::unique_ptr<runtime::FrameEvaluator> evaluator;
  std::unique_ptr<gpu::FrameRecorder> recorder;
  uint32_t characters = 0;
  bool normalMaps = false;
  // Frame bookkeeping: per slot, the frame last recorded into it and whether it was retired.
  struct SlotState {
    std::optional<uint64_t> frame;
    bool retired = true;
  };
  std::vector<SlotState> slots;
  std::optional<uint64_t> lastRecorded;
  // Scratch reused every frame (no allocation in the steady state beyond the evaluator's own).
  std::vector<Quatf> rotations;
  std::vector<float> dt;
  runtime::FrameKernelInputs inputs;
  // Quality levels: the model's ladder, each character's level and whether the host set it, and the
  // planner when swish chooses.
  runtime::QualityLadder ladder;
  std::vector<uint32_t> levels;
  std::vector<bool> hostLevel;
  std::optional<runtime::LevelPlanner> planner;
  std::vector<Eigen::Vector3d> roots;
};

// Which public code an internal error maps to, given where it happened.
ErrorCode classify(const swish::Error& e, ErrorCode fallback);

// Runs f, turning every exception into api::Error (internal Errors keep their message; Vulkan call
// failures become VulkanFailure; other errors get `fallback`).
template <class F>
auto translateErrors(ErrorCode fallback, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const api::Error&) {
    throw;
  } catch (const swish::Error& e) {
    throw api::Error(classify(e, fallback), e.what());
  } catch (const std::bad_alloc&) {
    throw api::Error(ErrorCode::VulkanFailure, "out of host memory");
  } catch (const std::exception& e) {
    throw api::Error(ErrorCode::Internal, e.what());
  }
}

// Conversions between public plain structs and internal types.
Quatf toQuatf(const Quat& q);
Mat4f toMat4f(const Mat4& m);
Mat4 toMat4(const Mat4f& m);
ModelInfo describeModel(const swish::Model& model, const std::string& name);

}  // namespace swish::api

namespace swish::api {
// The host's pose as a skeleton Pose: sizes checked (InvalidArgument), quaternions sanitised with the
// documented policy (normalised, or the REST rotation when NaN/zero), each fix appended to `warnings`
// when given. characterToWorld must be finite (InvalidArgument).
Pose toSkeletonPose(const swish::Model& model, const CharacterPose& pose, uint32_t character,
                    std::vector<std::string>* warnings);
}  // namespace swish::api
