#pragma once
// Frames and contact sheets of the preview, for `swish render` and `swish replay --render`.
//
// The hook for a replay loop (one model, one character drawn):
//   render::HostDevice device({.validation = false});
//   api::Runtime runtime = api::Runtime::adopt(device.handles());
//   api::Model model = runtime.loadModel(path);        // or loadModelFromMemory(serializeModel(m), name)
//   render::PreviewRenderer preview(device, runtime, model, options);   // options.body: bodyFromCharacter
//   per frame:  images.push_back(render::renderFramePng(preview, pose, dir / "frame_0001.png"));
//   at the end: render::writeContactSheet(images, dir / "contact_sheet.png", {});
#include <array>
#include <filesystem>
#include <vector>

#include "swish/render/preview_renderer.hpp"

namespace swish::render {

// Renders one frame of `pose` (normal map on, body when there is one), writes it as an RGB PNG
// (atomically) and returns the image, e.g. for a contact sheet.
PreviewImage renderFramePng(PreviewRenderer& preview, const api::CharacterPose& pose,
                            const std::filesystem::path& path);

struct ContactSheetOptions {
  uint32_t columns = 4;
  uint32_t thumbnailWidth = 240;  // each frame scaled to this width (box filter), aspect kept
  uint32_t gap = 4;               // pixels between thumbnails
  std::array<float, 3> background{0.93f, 0.94f, 0.96f};
};

// A grid of the frames in order, left to right then top to bottom. Frames must share one size.
PreviewImage makeContactSheet(const std::vector<PreviewImage>& frames, const ContactSheetOptions& options = {});
void writeContactSheet(const std::vector<PreviewImage>& frames, const std::filesystem::path& path,
                       const ContactSheetOptions& options = {});

}  // namespace swish::render
