#version 330 core
// The ramp lookup as a pass of its own over F's active blocks, after the Jacobi steps: where
// a pixel takes it, the last step again (jacobi.glsl), its result and the lookup by the
// model's confidence; every other pixel is discarded and keeps what the steps wrote (or F).
// Twin: ramp_lookup in aarecovery/spec/ramp_lookup.py. A pass of its own since the lookup
// acts wherever F varies, and with pure colours the steps cover only the live blocks; in a
// block they did not cover the confidence is 0 throughout and the step gives exactly F.
// On llvmpipe it costs what the lookup fused into the last step did (0.22 s over the 15 % of
// a 4096 x 4096 photo-like pair under a threshold that F's active blocks cover, where one
// pixel in a hundred takes the samples): reading O and F around each pixel, not the samples.
#include "working.glsl"
#include "jacobi.glsl"
#include "result_layout.glsl"
#include "ramp_lookup.glsl"

out vec4 result;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(filtered_work, 0);
    if (!filtered_varies(p, size)) discard;
    vec3 centre, along_x, along_y;
    if (!ramp_takes(p, size, centre, along_x, along_y)) discard;
    vec3 delta = ramp_average(centre, along_x, along_y);
    if (all(equal(delta, vec3(0.0)))) discard;
    vec4 straight = from_working(jacobi_step(p, size), p);
    result = result_texel(ramp_added(straight, delta, texelFetch(model_map, p, 0).y));
}
