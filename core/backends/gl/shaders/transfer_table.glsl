// The filter's table as a function of encoded colour: its keys and its output, for the pure
// colours of thin features and the ramp lookup. Twin: key_values, transfer_encoded and
// _table_at in aarecovery/spec/pure_colours.py. Needs colour.glsl.

#if TABLE_KEY == 9
uniform sampler3D transfer_table;  // B x B x B: a colour map, encoded output per bin of (R, G, B)
#else
uniform sampler2D transfer_table;  // 256 x 1: the filter's table, encoded output per key bin
#endif

// The key is a compile-time define, not a uniform: llvmpipe runs both sides of every branch
// under a mask, so a uniform switch paid for every key's sRGB conversions (pow) at every
// pixel.
// TABLE_KEY: 0: each channel indexes its own column, 1: luma indexes all,
//            4/5: encoded luminance (Rec. 709 / D50 weights) indexes all,
//            2/3: luma (encoded) / luminance (linear) mapped by column 0, colour scaled
//            with it (scale_transfer)
//            6/7: the 8-bit Rec. 601 grey (rounded / truncated) indexes an offset added to
//            every channel (SHIFT_KEYS, shift_grey)
//            8: the 8-bit Rec. 601 grey, rounded, indexes all (rec601_grey)
//            9: the whole colour indexes a 3-D table (colour_map_at: a palette quantiser)
#ifndef TABLE_KEY
#define TABLE_KEY 0
#endif
#define SCALE_KEY (TABLE_KEY == 2 || TABLE_KEY == 3)
#define SHIFT_KEY (TABLE_KEY == 6 || TABLE_KEY == 7)

// The tools' fixed-point Rec. 601 Y (spec.pure_colours._OPENCV_Y, _PILLOW_Y, _REC601_Y):
// weights and scale.
const vec4 OPENCV_Y = vec4(4899.0, 9617.0, 1868.0, 16384.0);
const vec4 PILLOW_Y = vec4(19.136, 37.568, 7.296, 64.0);
const vec4 REC601_Y = vec4(299.0, 587.0, 114.0, 1000.0);

#if TABLE_KEY == 9
// The 3-D table between bin centres (i + 0.5) / B, trilinearly: the corners in the
// specification's order, each weight a product over R, G, B (colour_map_at). The texture's
// x runs along B, its z along R.
vec3 colour_map_at(vec3 encoded) {
    int bins = textureSize(transfer_table, 0).x;
    vec3 position = clamp(encoded * float(bins) - 0.5, 0.0, float(bins - 1));
    ivec3 low = min(ivec3(position), ivec3(bins - 2));
    vec3 weight = position - vec3(low);
    vec3 result = vec3(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        ivec3 step = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        float corner_weight = 1.0;
        corner_weight *= step.x == 1 ? weight.x : 1.0 - weight.x;
        corner_weight *= step.y == 1 ? weight.y : 1.0 - weight.y;
        corner_weight *= step.z == 1 ? weight.z : 1.0 - weight.z;
        ivec3 bin = low + step;
        result += corner_weight * texelFetch(transfer_table, bin.zyx, 0).rgb;
    }
    return result;
}
#else
float table_at(float key, int channel) {
    // Linear interpolation between bin centres, two fetches (no texture filtering: llvmpipe's
    // filtering weights are not exact).
    float position = clamp(key * 256.0 - 0.5, 0.0, 255.0);
    int lower = min(int(floor(position)), 254);
    float fraction = position - float(lower);
    float below = texelFetch(transfer_table, ivec2(lower, 0), 0)[channel];
    float above = texelFetch(transfer_table, ivec2(lower + 1, 0), 0)[channel];
    return below + (above - below) * fraction;
}

// Every column at one key: two fetches instead of six, the same arithmetic per column.
vec3 table_row_at(float key) {
    float position = clamp(key * 256.0 - 0.5, 0.0, 255.0);
    int lower = min(int(floor(position)), 254);
    float fraction = position - float(lower);
    vec3 below = texelFetch(transfer_table, ivec2(lower, 0), 0).rgb;
    vec3 above = texelFetch(transfer_table, ivec2(lower + 1, 0), 0).rgb;
    return below + (above - below) * fraction;
}

#endif

// The table keys of an encoded colour, one per table column (key_values).
vec3 key_values(vec3 encoded) {
#if TABLE_KEY == 0 || TABLE_KEY == 9
    return encoded;
#elif SHIFT_KEY
    // The grey level as the tool computes it from the 8-bit channels, at its bin's centre
    // (shift_grey): whole numbers below 2^24, exact in float.
    vec3 levels = floor(clamp(encoded, 0.0, 1.0) * 255.0 + 0.5);
#if TABLE_KEY == 6
    float grey = floor((levels.r * OPENCV_Y.x + levels.g * OPENCV_Y.y + levels.b * OPENCV_Y.z + OPENCV_Y.w / 2.0)
                       / OPENCV_Y.w);
#else
    float grey = floor((floor(levels.r * PILLOW_Y.x + 0.5) + floor(levels.g * PILLOW_Y.y + 0.5)
                        + floor(levels.b * PILLOW_Y.z + 0.5)) / PILLOW_Y.w);
#endif
    grey = clamp(grey, 0.0, 255.0);
    return vec3((grey + 0.5) / 256.0);
#elif TABLE_KEY == 8
    // The rounded grey in thousandths (rec601_grey): whole numbers, exact in float.
    vec3 levels = floor(clamp(encoded, 0.0, 1.0) * 255.0 + 0.5);
    float grey = floor((levels.r * REC601_Y.x + levels.g * REC601_Y.y + levels.b * REC601_Y.z + REC601_Y.w / 2.0)
                       / REC601_Y.w);
    grey = clamp(grey, 0.0, 255.0);
    return vec3((grey + 0.5) / 256.0);
#elif TABLE_KEY == 4 || TABLE_KEY == 5
    // The encoded value of the luminance of linear light (LUMINANCE_KEYS).
    vec3 weights = TABLE_KEY == 4 ? LUMA : LUMINANCE_D50;
    vec3 lin = srgb_to_linear(encoded);
    return linear_to_srgb(vec3(lin.r * weights.r + lin.g * weights.g + lin.b * weights.b));
#else
    vec3 values = TABLE_KEY == 3 ? srgb_to_linear(encoded) : encoded;
    return vec3(values.r * LUMA.r + values.g * LUMA.g + values.b * LUMA.b);
#endif
}

// f of an encoded colour at its (perhaps clamped) table keys, encoded (transfer_encoded).
vec3 transfer_encoded(vec3 encoded, vec3 keys) {
#if SCALE_KEY
    vec3 values = TABLE_KEY == 3 ? srgb_to_linear(encoded) : encoded;
    float luma = values.r * LUMA.r + values.g * LUMA.g + values.b * LUMA.b;
    float mapped = table_at(keys.r, 0);
    vec3 scaled = luma > 1e-6 ? values * (mapped / luma) : vec3(mapped);
    scaled = clamp(scaled, 0.0, 1.0);
    return TABLE_KEY == 3 ? linear_to_srgb(scaled) : scaled;
#elif SHIFT_KEY
    return clamp(encoded + vec3(table_at(keys.r, 0)), 0.0, 1.0);
#elif TABLE_KEY == 0
    return vec3(table_at(keys.r, 0), table_at(keys.g, 1), table_at(keys.b, 2));
#elif TABLE_KEY == 9
    return colour_map_at(encoded);
#else
    return table_row_at(keys.r);  // one key for all columns
#endif
}
