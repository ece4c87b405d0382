# cmake -DIN=file.spv -DOUT=file.cpp -DSYMBOL=name -P EmbedSpirv.cmake
# Writes the SPIR-V words of IN as a uint32_t array (SPIR-V is a stream of little-endian words).
file(READ ${IN} hex HEX)
string(LENGTH "${hex}" len)
math(EXPR rem "${len} % 8")
if(NOT rem EQUAL 0)
  message(FATAL_ERROR "${IN}: size is not a multiple of 4 bytes, not SPIR-V")
endif()
# Each 8 hex digits are 4 bytes b0 b1 b2 b3 -> word 0xb3b2b1b0.
string(REGEX REPLACE "([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])" "0x\\4\\3\\2\\1u," words "${hex}")
math(EXPR count "${len} / 8")
file(WRITE ${OUT} "// Generated from ${IN}. Do not edit.\n#include <cstddef>\n#include <cstdint>\nnamespace swish::shaders {\nextern const uint32_t ${SYMBOL}_words[] = {${words}};\nextern const size_t ${SYMBOL}_count = ${count};\n}\n")
