#version 330 core
// One pass of the local plan's factor over the whole image (local_plan.glsl does the work).
#if REGION_GATHER
// Where the backend asks for it, its context has GL 4.0, which includes the extension.
#extension GL_ARB_texture_gather : require
#endif
#include "colour.glsl"
#include "local_plan.glsl"

layout(location = 0) out vec4 value;

void main() {
#if LOCAL_PASS == 1
    ivec2 size = textureSize(original_image, 0);
#else
    ivec2 size = textureSize(local_input, 0);
#endif
    value = vec4(local_plan(ivec2(gl_FragCoord.xy), size), 1.0);
}
