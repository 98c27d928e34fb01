// Exact piecewise sRGB transfer functions (IEC 61966-2-1) and the luma weights: the GL
// backend's only colour maths. The NumPy twin is aarecovery/colour.py.

const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);  // Rec. 709 (aarecovery.colour.LUMA)
const vec3 LUMINANCE_D50 = vec3(0.2225045, 0.7168786, 0.0606169);  // babl's Y (aarecovery.colour)

vec3 srgb_to_linear(vec3 encoded) {
    vec3 low = encoded * (1.0 / 12.92);
    vec3 high = pow((max(encoded, 0.0) + 0.055) * (1.0 / 1.055), vec3(2.4));
    return mix(high, low, lessThanEqual(encoded, vec3(0.04045)));
}

vec3 linear_to_srgb(vec3 linear) {
    linear = clamp(linear, 0.0, 1.0);
    vec3 low = linear * 12.92;
    vec3 high = 1.055 * pow(linear, vec3(1.0 / 2.4)) - 0.055;
    return mix(high, low, lessThanEqual(linear, vec3(0.0031308)));
}

#define CONVERT_NONE 0
#define CONVERT_DECODE 1
#define CONVERT_ENCODE 2

// `mode` is always a compile-time constant, so the branches fold away.
vec3 convert_colour(vec3 colour, int mode) {
    if (mode == CONVERT_DECODE) return srgb_to_linear(colour);
    if (mode == CONVERT_ENCODE) return linear_to_srgb(colour);
    return colour;
}

// Straight RGBA into the working space: colour converted by `mode`, then premultiplied.
// Twin: to_working_space in aarecovery/spec/working_space.py.
vec4 to_working(vec4 straight, int mode) {
    straight = clamp(straight, 0.0, 1.0);  // float inputs may stray a hair outside [0, 1]
    return vec4(convert_colour(straight.rgb, mode) * straight.a, straight.a);
}
