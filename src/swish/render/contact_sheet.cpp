#include "swish/render/contact_sheet.hpp"

#include <algorithm>
#include <cmath>

#include "swish/api_error.hpp"

namespace swish::render {

PreviewImage renderFramePng(PreviewRenderer& preview, const api::CharacterPose& pose,
                            const std::filesystem::path& path) {
  PreviewImage img = preview.render(pose, {{true, true}});
  writePreviewPng(path.string(), img, preview.options().background);
  return img;
}

PreviewImage makeContactSheet(const std::vector<PreviewImage>& frames, const ContactSheetOptions& o) {
  if (frames.empty()) throw api::Error(api::ErrorCode::InvalidArgument, "contact sheet: no frames");
  if (o.columns == 0 || o.thumbnailWidth == 0)
    throw api::Error(api::ErrorCode::InvalidArgument, "contact sheet: columns and thumbnail width must be >= 1");
  const uint32_t fw = frames[0].width, fh = frames[0].height;
  for (const auto& f : frames)
    if (f.width != fw || f.height != fh)
      throw api::Error(api::ErrorCode::InvalidArgument, "contact sheet: frames differ in size");
  const uint32_t tw = std::min(o.thumbnailWidth, fw);
  const uint32_t th = std::max<uint32_t>(1, uint32_t(std::lround(double(fh) * tw / fw)));
  const uint32_t cols = std::min<uint32_t>(o.columns, uint32_t(frames.size()));
  const uint32_t rows = uint32_t((frames.size() + cols - 1) / cols);
  PreviewImage sheet;
  sheet.width = cols * tw + (cols + 1) * o.gap;
  sheet.height = rows * th + (rows + 1) * o.gap;
  sheet.rgba.assign(size_t(sheet.width) * sheet.height * 4, 0);  // alpha 0: background
  for (size_t i = 0; i < frames.size(); ++i) {
    const uint32_t ox = o.gap + uint32_t(i % cols) * (tw + o.gap), oy = o.gap + uint32_t(i / cols) * (th + o.gap);
    for (uint32_t y = 0; y < th; ++y)
      for (uint32_t x = 0; x < tw; ++x) {
        // Box filter over the source texels this thumbnail pixel covers (premultiplied by alpha).
        const uint32_t x0 = x * fw / tw, x1 = std::max(x0 + 1, (x + 1) * fw / tw);
        const uint32_t y0 = y * fh / th, y1 = std::max(y0 + 1, (y + 1) * fh / th);
        double acc[4] = {0, 0, 0, 0};
        for (uint32_t sy = y0; sy < y1; ++sy)
          for (uint32_t sx = x0; sx < x1; ++sx) {
            const uint8_t* p = &frames[i].rgba[(size_t(sy) * fw + sx) * 4];
            const double a = p[3] / 255.0;
            for (int c = 0; c < 3; ++c) acc[c] += p[c] * a;
            acc[3] += a;
          }
        const double n = double(x1 - x0) * (y1 - y0);
        uint8_t* d = &sheet.rgba[(size_t(oy + y) * sheet.width + ox + x) * 4];
        for (int c = 0; c < 3; ++c) d[c] = uint8_t(std::lround(acc[3] > 0 ? acc[c] / acc[3] : 0));
        d[3] = uint8_t(std::lround(255.0 * acc[3] / n));
      }
  }
  return sheet;
}

void writeContactSheet(const std::vector<PreviewImage>& frames, const std::filesystem::path& path,
                       const ContactSheetOptions& o) {
  writePreviewPng(path.string(), makeContactSheet(frames, o), o.background);
}

}  // namespace swish::render
