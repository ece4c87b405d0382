#pragma once
// Internal to the .swish reader/writer: one encoder and one decoder per section payload of the
// format described in model_file.hpp. The container (header, section table, checksums) lives in
// model_file.cpp; this is only what goes inside each section.
#include <string_view>
#include <vector>

#include "swish/files/byte_reader.hpp"
#include "swish/files/byte_writer.hpp"
#include "swish/model/model.hpp"

namespace swish::model_sections {

struct SectionCodec {
  std::string_view tag;  // 4 ASCII characters
  void (*write)(const Model&, ByteWriter&);
  // Reads the whole payload into the model (the container checks that nothing is left over).
  void (*read)(ByteReader&, Model&);
};

// The sections of the current format version, in the order the writer emits them.
const std::vector<SectionCodec>& sectionCodecs();

}  // namespace swish::model_sections
