#version 330 core
// The model fit as a fragment pass over the active blocks (blend_model.glsl does the work).
#if LIVE_BLOCKS
// Storage buffers in a 3.30 shader: where the backend flags live blocks, its context has
// GL 4.3, whose drivers offer both extensions.
#extension GL_ARB_shader_storage_buffer_object : require
#extension GL_ARB_shading_language_420pack : require
#endif
#include "working.glsl"
#include "sobel.glsl"
#if PURE_COLOURS
#include "pure_colours.glsl"
#endif
#include "blend_model.glsl"
#if LIVE_BLOCKS
#include "live_blocks.glsl"
#endif

layout(location = 0) out vec4 model;
layout(location = 1) out vec4 first_iterate;
#if MAPS
layout(location = 2) out vec4 edge_map;       // edge strength in .r
#endif
#if JACOBI_CONSTANT
layout(location = CONSTANT_LOCATION) out vec4 jacobi_constant;
#endif

void main() {
    BlendFit fit = fit_blend_model(ivec2(gl_FragCoord.xy), textureSize(filtered_work, 0));
    model = fit.model;
    first_iterate = fit.first_iterate;
#if LIVE_BLOCKS
    flag_live(ivec2(gl_FragCoord.xy), fit, textureSize(filtered_work, 0));
#endif
#if MAPS
    edge_map = vec4(fit.edge, 0.0, 0.0, 1.0);
#endif
#if JACOBI_CONSTANT
    jacobi_constant = fit.jacobi_constant;
#endif
}
