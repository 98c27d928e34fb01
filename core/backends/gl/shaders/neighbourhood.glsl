// The 3x3 neighbourhood every pass reads. Twin: aarecovery/spec/neighbourhood.py.

// Neighbourhood order of NEIGHBOUR_OFFSETS (x = column, y = row): centre, N, W, E, S, NW, NE, SW, SE.
const ivec2 OFFSETS[9] = ivec2[9](
    ivec2(0, 0), ivec2(0, -1), ivec2(-1, 0), ivec2(1, 0), ivec2(0, 1),
    ivec2(-1, -1), ivec2(1, -1), ivec2(-1, 1), ivec2(1, 1));

// Borders replicate edge pixels.
ivec2 clamp_to_image(ivec2 p, ivec2 size) {
    return clamp(p, ivec2(0), size - 1);
}

// The offsets of a pixel's two extremes (a.x, a.y, b.x, b.y, each -1..1) from the model's
// code (blend_model.glsl), its pure colours' part (81, 162) taken off first. Decoded in float
// arithmetic: integer division and indexing an array by a variable are scalar code on a
// CPU's vector units (llvmpipe).
float extremes_code(float code) {
    return code - 81.0 * floor((code + 0.5) * (1.0 / 81.0));
}

vec4 extreme_offsets(float code) {
    vec4 digits = floor((code + 0.5) / vec4(1.0, 3.0, 9.0, 27.0));
    return digits - 3.0 * floor(digits * (1.0 / 3.0)) - 1.0;
}
