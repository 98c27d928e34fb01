// The image view: one or two "layers" side by side (the split view), each showing an image,
// one channel of a map, or a heat-map of the difference of two images.
//
// The program is compiled once per layer configuration: ImageView prepends "#version 330 core"
// and these defines, so that the compiler drops every branch the configuration does not use
// (on llvmpipe a uniform-driven branch still costs both sides):
//   SPLIT                      1: layer 1 right of the divider; 0: layer 0 everywhere
//   KIND0, KIND1               KIND_COLOUR, KIND_MAP or KIND_DIFFERENCE
//   CHANNEL0, CHANNEL1         the channel holding a map (KIND_MAP)
//   LINEAR0_A, LINEAR0_B, ...  1 when that texture holds linear light (encoded for display)
//
// Texels are read with texelFetch at whole-texel positions, so magnification is nearest
// neighbour by construction; when zoomed out, a few texels under each screen pixel are
// averaged so that fine detail does not shimmer. Texture row 0 is image row 0 (the top), as
// NumPy arrays are uploaded.

#define KIND_COLOUR 0       // an RGBA image over a checkerboard
#define KIND_MAP 1          // one channel, times a gain, as grey
#define KIND_DIFFERENCE 2   // max over channels of |a - b| on display values, times a gain
const int MAX_FOOTPRINT = 2;  // most texels averaged per axis when zoomed out

uniform vec4 u_area;           // image area in the framebuffer: x, y (bottom-up), width, height
uniform vec2 u_offset;         // view position of the image's top-left corner (y down)
uniform float u_zoom;          // view pixels per image pixel
uniform float u_split_x;       // view x of the divider
uniform vec3 u_background;
uniform vec2 u_gain;           // per layer: map or difference scale

uniform sampler2D u_layer0_a;
uniform sampler2D u_layer0_b;
uniform sampler2D u_layer1_a;
uniform sampler2D u_layer1_b;

out vec4 f_colour;

// The sRGB transfer function (IEC 61966-2-1): linear light to display values.
vec3 srgb_encode(vec3 linear) {
    vec3 c = clamp(linear, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

vec4 display_rgba(vec4 texel, int linear) {
    return linear == 1 ? vec4(srgb_encode(texel.rgb), texel.a) : texel;
}

// Black at zero through red and yellow to white: zero difference must read as nothing.
vec3 heat(float value) {
    float v = clamp(value, 0.0, 1.0);
    return clamp(vec3(3.0 * v, 3.0 * v - 1.0, 3.0 * v - 2.0), 0.0, 1.0);
}

vec3 checkerboard(vec2 view_position) {
    ivec2 cell = ivec2(floor(view_position / 8.0));
    return ((cell.x + cell.y) & 1) == 0 ? vec3(0.40) : vec3(0.60);
}

// `kind`, `channel` and the linear flags are compile-time constants at every call.
vec3 layer_colour(int kind, int channel, int linear_a, int linear_b, float gain,
                  sampler2D a, sampler2D b, ivec2 texel, vec2 view_position) {
    vec4 value_a = texelFetch(a, texel, 0);
    if (kind == KIND_MAP) {
        return vec3(clamp(value_a[channel] * gain, 0.0, 1.0));
    }
    vec4 shown_a = display_rgba(value_a, linear_a);
    if (kind == KIND_DIFFERENCE) {
        vec4 difference = abs(shown_a - display_rgba(texelFetch(b, texel, 0), linear_b));
        return heat(max(max(difference.r, difference.g), max(difference.b, difference.a)) * gain);
    }
    return mix(checkerboard(view_position), shown_a.rgb, shown_a.a);
}

vec3 layer_at(bool right, ivec2 texel, vec2 view_position) {
#if SPLIT
    if (right) {
        return layer_colour(KIND1, CHANNEL1, LINEAR1_A, LINEAR1_B, u_gain.y, u_layer1_a, u_layer1_b,
                            texel, view_position);
    }
#endif
    return layer_colour(KIND0, CHANNEL0, LINEAR0_A, LINEAR0_B, u_gain.x, u_layer0_a, u_layer0_b,
                        texel, view_position);
}

void main() {
    vec2 area_position = gl_FragCoord.xy - u_area.xy;
    vec2 view_position = vec2(area_position.x, u_area.w - area_position.y);  // y down, pixel centre
    bool right = view_position.x >= u_split_x;
    ivec2 size = textureSize(u_layer0_a, 0);

    vec2 image_position = (view_position - u_offset) / u_zoom;
    if (any(lessThan(image_position, vec2(0.0))) || any(greaterThanEqual(image_position, vec2(size)))) {
        f_colour = vec4(u_background, 1.0);
        return;
    }
    // Texels per screen pixel along each axis: 1 when magnified, up to MAX_FOOTPRINT when not.
    int footprint = clamp(int(ceil(1.0 / u_zoom - 1e-4)), 1, MAX_FOOTPRINT);
    if (footprint == 1) {
        f_colour = vec4(layer_at(right, ivec2(floor(image_position)), view_position), 1.0);
        return;
    }
    vec2 pixel_corner = (view_position - 0.5 - u_offset) / u_zoom;
    float step_size = 1.0 / (u_zoom * float(footprint));
    vec3 total = vec3(0.0);
    for (int j = 0; j < footprint; ++j) {
        for (int i = 0; i < footprint; ++i) {
            vec2 sample_position = pixel_corner + (vec2(i, j) + 0.5) * step_size;
            ivec2 texel = clamp(ivec2(floor(sample_position)), ivec2(0), size - 1);
            total += layer_at(right, texel, view_position);
        }
    }
    f_colour = vec4(total / float(footprint * footprint), 1.0);
}
