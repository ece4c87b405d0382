#version 460
// Benchmark: an empty kernel, to measure the fixed cost of one dispatch.
layout(local_size_x = 64) in;
void main() {}
