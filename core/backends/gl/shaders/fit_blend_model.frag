#version 330 core
// The model fit as a fragment pass over the active blocks (blend_model.glsl does the work).
#include "working.glsl"
#include "sobel.glsl"
#if PURE_COLOURS
#include "pure_colours.glsl"
#endif
#include "blend_model.glsl"

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
#if MAPS
    edge_map = vec4(fit.edge, 0.0, 0.0, 1.0);
#endif
#if JACOBI_CONSTANT
    jacobi_constant = fit.jacobi_constant;
#endif
}
