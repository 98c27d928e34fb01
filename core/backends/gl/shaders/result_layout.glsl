// A straight RGBA result as a texel of the result texture, which has RESULT_CHANNELS: F's
// own layout where the texture can take it (grey+alpha keeps its alpha in the second
// channel), RGBA otherwise; reading it back then needs no conversion on the CPU.
vec4 result_texel(vec4 straight) {
#if RESULT_CHANNELS == 2
    return vec4(straight.r, straight.a, 0.0, 1.0);
#else
    return straight;
#endif
}
