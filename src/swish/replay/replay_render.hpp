#pragma once
// `swish replay --render`: draws one scene character's frames with the headless preview renderer (a
// host of the public API on its own Vulkan device) and writes them as PNG frames plus a contact sheet.
// The character is drawn in place (its root at the rest position, facing the camera), so the fixed
// preview camera keeps it framed however far the play carries it across the field: the camera frames the
// garment and the upper body around it (arms included), not the whole figure on a large canvas.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "swish/replay/body_through_garment.hpp"
#include "swish/replay/model_library.hpp"
#include "swish/replay/truth_simulation.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

struct ReplayRenderOptions {
  uint32_t character = 0;   // scene character index
  uint32_t maxFrames = 16;  // frames are spread evenly over the scene when it has more
  uint32_t width = 320, height = 426;
  std::string device;  // as --device
  bool validation = false;
  // With truth.every > 0 (`--truth-every N`): the drawn frames are taken on the truth grid, and each also
  // gets an error figure heat_NNNN.png (model, truth, per-vertex error heat map with its mm legend;
  // io/error_heat_map.hpp) and heat_sheet.png; the truth is simulated again here (as the replay's).
  TruthOptions truth;
  bool pushOut = false;  // as the replay's --push-out
  // Leave out the body triangles the garment covers in (nearly) every training pose (the model's list: games
  // do not draw the skin under tight clothing). Off by default: a body showing through is a fault the
  // user should see; the result's note says which was drawn.
  bool hideCoveredBody = false;
};

struct ReplayRenderResult {
  std::vector<std::filesystem::path> frames;
  std::vector<uint32_t> frameNumbers;  // the scene frame of each drawn frame
  // Per drawn frame: the pixels where skin the garment covers at rest is drawn (body_through_garment.hpp);
  // empty when no body is drawn. `coveredTriangles`: how many body triangles the garment covers at rest.
  std::vector<BodyThroughGarment> bodyThrough;
  std::vector<std::filesystem::path> throughFrames;  // per frame that shows any: through_NNNN.png, those pixels marked
  size_t coveredTriangles = 0;
  // With truth and a body: per drawn frame, the same measure on the truth's garment posed and seen as the
  // model's was (nullopt where the frame has no truth or its simulation failed), so the report tells whether
  // the model or its source simulation puts the body through the cloth.
  std::vector<std::optional<BodyThroughGarment>> truthBodyThrough;
  std::filesystem::path contactSheet;
  std::filesystem::path throughSheet;  // the through_NNNN.png frames on one sheet; empty when none
  // With truth: per frame whose truth shows any, truth_through_NNNN.png (the truth's counted pixels painted on
  // the model's frame), and those on one sheet.
  std::vector<std::filesystem::path> truthThroughFrames;
  std::filesystem::path truthThroughSheet;
  std::vector<std::filesystem::path> heatMaps;  // per frame with truth
  std::filesystem::path heatSheet;              // empty without truth
  std::string note;                             // e.g. why no body was drawn, or why there are no heat maps
};

// Writes `directory`/frame_NNNN.png and `directory`/contact_sheet.png. Throws Error naming the scene
// and character for a bad index or a character without a clip/stream; on any error the folder is removed.
ReplayRenderResult renderReplayFrames(const runtime::Scene& scene, ModelLibrary& models,
                                      const std::filesystem::path& directory, const ReplayRenderOptions& options);

// The report's section on the pictures (Markdown, links relative to `reportDirectory`): which character,
// what the body shows (whole, or the covered triangles left out), whether the push-out ran, how many
// frames show the body through the garment (and the pixels of each), the sheets.
std::string renderReportSection(const ReplayRenderResult& result, const ReplayRenderOptions& options,
                                const std::filesystem::path& reportDirectory);

}  // namespace swish::replay
