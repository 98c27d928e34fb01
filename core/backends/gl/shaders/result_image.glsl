// The result image a compute pass writes: the result texture's format (RESULT_FORMAT: F's
// bit depth, and F's channels where it can, result_layout.glsl).
#include "result_layout.glsl"
layout(RESULT_FORMAT, binding = 0) uniform writeonly image2D result_image;
