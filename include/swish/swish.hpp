#pragma once
// The public interface of swish for host renderers: include this one header (or its parts) from
// include/swish/. Everything under src/ is private. Guide: docs/integration.md; example:
// examples/minimal_host.cpp.
#include "swish/api_error.hpp"
#include "swish/api_runtime.hpp"
#include "swish/api_types.hpp"
