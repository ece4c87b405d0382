// Model: a loaded, validated, uploaded .swish model; the factory of CharacterBatches.
#include <cmath>

#include "swish/api/api_impl.hpp"
#include "swish/core/rotation.hpp"

namespace swish::api {

Pose toSkeletonPose(const swish::Model& model, const CharacterPose& in, uint32_t character,
                    std::vector<std::string>* warnings) {
  const Skeleton& sk = model.skeleton;
  if (in.localRotations.size() != sk.size())
    throw Error(ErrorCode::InvalidArgument,
                "character " + std::to_string(character) + ": " + std::to_string(in.localRotations.size()) +
                    " joint rotations, the model's skeleton has " + std::to_string(sk.size()));
  for (float v : in.characterToWorld)
    if (!std::isfinite(v))
      throw Error(ErrorCode::InvalidArgument,
                  "character " + std::to_string(character) + ": characterToWorld is not finite");
  Pose p;
  p.local.resize(sk.size());
  for (size_t j = 0; j < sk.size(); ++j) {
    const SanitizedQuat s = sanitizeQuaternion(toQuatf(in.localRotations[j]));
    if (s.status == QuatStatus::Invalid) {
      p.local[j] = sk.joints[j].rest.rotation;  // a broken rotation shows the rest pose, not a twist
      if (warnings)
        warnings->push_back("character " + std::to_string(character) + ", joint '" + sk.joints[j].name +
                            "': NaN/Inf or zero quaternion replaced by the rest rotation");
    } else {
      p.local[j] = s.q;
      if (s.status == QuatStatus::Renormalised && warnings)
        warnings->push_back("character " + std::to_string(character) + ", joint '" + sk.joints[j].name +
                            "': non-unit quaternion normalised");
    }
  }
  const int root = sk.size() ? 0 : -1;
  p.rootTranslation = root >= 0 ? sk.joints[0].rest.translation : Vec3f::Zero();
  if (in.rootTranslation) {
    const auto& t = *in.rootTranslation;
    if (std::isfinite(t[0]) && std::isfinite(t[1]) && std::isfinite(t[2])) {
      p.rootTranslation = Vec3f(t[0], t[1], t[2]);
    } else if (warnings) {
      warnings->push_back("character " + std::to_string(character) +
                          ": non-finite root translation replaced by the rest one");
    }
  }
  return p;
}

Model::Model(std::shared_ptr<ModelImpl> impl) : impl_(std::move(impl)) {}

const ModelInfo& Model::info() const { return impl_->info; }

std::vector<Mat4> Model::skinningMatrices(const CharacterPose& pose) const {
  return translateErrors(ErrorCode::InvalidArgument, [&] {
    const Pose p = toSkeletonPose(impl_->model, pose, 0, nullptr);
    const Mat4f world = toMat4f(pose.characterToWorld);
    std::vector<Mat4> out;
    for (const Mat4f& m : impl_->model.skeleton.skinningMatrices(p)) out.push_back(toMat4(world * m));
    return out;
  });
}

CharacterBatch Model::createBatch(const BatchOptions& o) const {
  return translateErrors(ErrorCode::InvalidArgument, [&] {
    if (o.characters == 0) throw Error(ErrorCode::InvalidArgument, "createBatch: a batch needs at least 1 character");
    if (o.framesInFlight < 1 || o.framesInFlight > 8)
      throw Error(ErrorCode::InvalidArgument,
                  "createBatch: " + std::to_string(o.framesInFlight) + " frames in flight; supported: 1..8");
    auto b = std::make_unique<BatchImpl>();
    b->model = impl_;
    b->characters = o.characters;
    b->inputs.pushOut = o.pushOut;
    b->normalMaps = o.normalMaps && impl_->gpuModel->hasNormalMaps() && impl_->runtime->ctx.supportsNormalMaps();
    runtime::FrameEvaluatorOptions eo;
    eo.guard = o.noveltyGuard;
    b->evaluator = std::make_unique<runtime::FrameEvaluator>(impl_->model, o.characters, eo);
    gpu::FrameRecorderOptions ro;
    ro.framesInFlight = o.framesInFlight;
    ro.tangentFrames = true;
    ro.normalMaps = b->normalMaps;
    b->recorder = std::make_unique<gpu::FrameRecorder>(impl_->runtime->ctx, *impl_->gpuModel, o.characters, ro);
    b->slots.resize(o.framesInFlight);
    return CharacterBatch(std::move(b));
  });
}

}  // namespace swish::api
