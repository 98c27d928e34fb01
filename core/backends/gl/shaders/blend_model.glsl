// Section 3.1 and equation 5 at one pixel: the two-colour blend model of O, its confidence,
// and the first Jacobi iterate (R0 = F), formed from the F texels fetched for Sobel.
// Twin: fit_blend_model and jacobi_step(F, F, model) in aarecovery/spec/passes.py.
// Needs working.glsl and sobel.glsl first, and pure_colours.glsl with PURE_COLOURS.

uniform float sigma_d;
uniform float sigma_e;
uniform float strength;  // the safe default's per-image repair strength; 1 for the paper
// Above 0, beta falls to 0 where F's pixel is O's and F moved its extremes by at most
// UNTOUCHED_EXTREMES (a smoothing filter's untouched edges, aarecovery.plan.smoothing): a
// smoothstep of F's largest channel change up to this, last. Twin: untouched_factor.
uniform float untouched_span;
#if LOCAL_STRENGTH
// The local plan's per-pixel factor of beta (aarecovery.spec.local_plan), after the strength,
// in .r; its regions' weight, which gates pure colours on drawn content only, in .g.
uniform sampler2D strength_factor;
#endif

const float TINY = 1e-12;
const float FAINT = 1e-30;
const float SPREAD_TIE = 1e-3;        // a start further by less is a tie: the first wins
const float SPREAD_TIE_FLOOR = 1e-6;
const float UNTOUCHED_EXTREMES = 0.1;  // F moved the extremes by at most this: untouched_factor applies
const float KEPT_EXTREMES = 0.1;       // F at the extremes this near O's line: towards O applies
#if TOWARD_ORIGINAL
// How far `colour` lies from the segment between O's extremes c_a and c_b (twin: _off_the_line).
float off_the_line(vec4 colour, vec4 c_a, vec4 c_b) {
    vec4 span = c_a - c_b;
    float span_sq = dot(span, span);
    float t = span_sq > TINY ? dot(colour - c_b, span) / span_sq : 0.0;
    vec4 off = colour - (c_b + clamp(t, 0.0, 1.0) * span);
    return sqrt(dot(off, off));
}

// The weight of O's own colour towards O: the largest gate of drawn content over the pixel's
// 3 x 3 neighbourhood, or of the kept ink (local_plan.glsl's third channel, 0 where the local
// plan did not read it) (twin: toward_weight in aarecovery/spec/blend_model.py). Read where the
// edge strength is above 0 only: O and F (or a ridge of O) differ within a pixel there, so
// every neighbour lies in a block the fit lists (margins of 2: blocks.active_mask and
// pure_colour_mask), where the local plan's last pass wrote the gate.
float toward_weight(ivec2 p, ivec2 size) {
    float weight = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec4 read = texelFetch(strength_factor, clamp_to_image(p + ivec2(dx, dy), size), 0);
            weight = max(weight, max(read.g, read.b));
        }
    }
    return weight;
}
#endif

#if BEST_PAIR
// Where the principal line misses the centre by more than BEST_PAIR_MISS sigma_d, the pair of
// neighbours that explains it best (twin: best_pair in aarecovery/spec/blend_model.py).
const float BEST_PAIR_MISS = 0.1;
const float BEST_PAIR_GAIN = 0.5;
const float BEST_PAIR_SPAN = 0.5;
const float BEST_PAIR_COVERAGE = 0.02;
const float BEST_PAIR_TIE = 2e-2;       // on squared misses
const float BEST_PAIR_TIE_FLOOR = 1e-5;

// The best pair so far: its squared miss of the centre, the centre's coverage of its first
// colour, and the two neighbours' indices (first < second).
struct BestPair { float miss_sq; float alpha; int a; int b; };

// Pair (i, j) of neighbours replaces `best` where it spans at least `least_span` (squared),
// holds the centre strictly inside and misses it by less, beyond a near tie. The miss is
// measured as the line's is (the blend minus the centre): by Pythagoras from dot products it
// cancelled to 3e-8, and near ties fell on either side between the backends.
void try_pair(inout BestPair best, vec4 centre, vec4 c_i, vec4 c_j, int i, int j, float least_span) {
    vec4 pair_span = c_i - c_j;
    float span_sq = dot(pair_span, pair_span);
    if (span_sq < least_span) return;
    float pair_alpha = dot(centre - c_j, pair_span) / span_sq;
    vec4 blend = pair_alpha * c_i + (1.0 - pair_alpha) * c_j - centre;
    float miss_sq = dot(blend, blend);
    if (pair_alpha > BEST_PAIR_COVERAGE && pair_alpha < 1.0 - BEST_PAIR_COVERAGE
        && miss_sq < best.miss_sq - max(best.miss_sq * BEST_PAIR_TIE, BEST_PAIR_TIE_FLOOR)) {
        best = BestPair(miss_sq, pair_alpha, i, j);
    }
}
#endif

struct BlendFit {
    vec4 model;           // alpha, beta, the extremes' offsets (+ 81, 162: pure colours), residual
    vec4 first_iterate;   // working space
    float edge;           // edge strength e_p
    vec4 jacobi_constant; // with pure colours: (1 - beta) F plus beta's share of the fixed
                          // pure colours (towards O: (1 - beta - g) F + g O for (1 - beta) F),
                          // the part of every Jacobi step that R does not change
    bool live;            // a Jacobi step here can give other than F (live_blocks.glsl)
};

// Roweis EM for one component is power iteration on the 4x4 scatter matrix (see the NumPy
// twin, principal_direction), started at the neighbour farthest from the mean.
vec4 principal_direction(vec4 c[9]) {
    vec4 mean = vec4(0.0);
    for (int i = 0; i < 9; ++i) mean += c[i];
    mean /= 9.0;
    vec4 x = vec4(0.0);
    float farthest = -1.0;  // the centre (i = 0) always starts
    float s00 = 0.0, s01 = 0.0, s02 = 0.0, s03 = 0.0, s11 = 0.0, s12 = 0.0, s13 = 0.0;
    float s22 = 0.0, s23 = 0.0, s33 = 0.0;
    for (int i = 0; i < 9; ++i) {
        vec4 y = c[i] - mean;
        float spread = dot(y, y);
        if (spread > farthest + max(farthest * SPREAD_TIE, SPREAD_TIE_FLOOR)) { farthest = spread; x = y; }
        s00 += y.x * y.x; s01 += y.x * y.y; s02 += y.x * y.z; s03 += y.x * y.w;
        s11 += y.y * y.y; s12 += y.y * y.z; s13 += y.y * y.w;
        s22 += y.z * y.z; s23 += y.z * y.w; s33 += y.w * y.w;
    }
    for (int iteration = 0; iteration < 3; ++iteration) {
        x = vec4(s00 * x.x + s01 * x.y + s02 * x.z + s03 * x.w,
                 s01 * x.x + s11 * x.y + s12 * x.z + s13 * x.w,
                 s02 * x.x + s12 * x.y + s22 * x.z + s23 * x.w,
                 s03 * x.x + s13 * x.y + s23 * x.z + s33 * x.w);
        x = x / sqrt(dot(x, x) + FAINT);
    }
    return x;
}

// Equation 5 times the strength.
float confidence(float residual, float edge) {
    float edge_ratio = edge / sigma_e;
    float residual_ratio = residual / sigma_d;
    float beta = exp(-residual_ratio * residual_ratio) * (1.0 - exp(-edge_ratio * edge_ratio));
    if (strength != 1.0) beta *= strength;
    return beta;
}

BlendFit fit_blend_model(ivec2 p, ivec2 size) {
    BlendFit fit;
    // F first: where F is flat the edge strength is exactly 0, so beta is 0 and the model
    // is never used; skipping the fit there is what makes thresholded and posterized
    // images (mostly flat) fast.
    vec4 f[9];
    for (int i = 0; i < 9; ++i) f[i] = filtered_neighbour(p, i, size);
    float filtered_gradient = sobel_magnitude(f);
    vec4 c[9];
    float edge = 0.0;
#if PURE_COLOURS
    // With pure colours, a thin feature that the filter erased leaves F flat where it must
    // be restored: only a flat O means there is nothing to fit (see fit_pure_colour_model).
    // A thin feature centred on p has no Sobel gradient: its ridge magnitude stands in.
#if PURE_GATE
    float gate = texelFetch(strength_factor, p, 0).g;  // the regions' weight (local_plan.glsl)
#else
    float gate = 1.0;
#endif
    for (int i = 0; i < 9; ++i) c[i] = original_neighbour(p, i, size);
    float original_gradient = max(sobel_magnitude(c), ridge_magnitude(c) * RIDGE_EDGE_SCALE * gate);
    edge = original_gradient * filtered_gradient;
    if (original_gradient == 0.0) {
#else
    if (filtered_gradient > 0.0) {
        for (int i = 0; i < 9; ++i) c[i] = original_neighbour(p, i, size);
        edge = sobel_magnitude(c) * filtered_gradient;
    }
    if (edge == 0.0) {
#endif
        fit.edge = edge;
        fit.model = vec4(0.5, 0.0, 0.0, 0.0);
        fit.first_iterate = f[0];
        fit.jacobi_constant = f[0];
        fit.live = false;
        return fit;
    }

    vec4 x = principal_direction(c);

    // Extremes along the line through the centre, among neighbours within 3 sigma_d of it;
    // the first of equal candidates wins (centre, then 4-neighbours, then diagonals).
    // Extremes are carried as values, not indices: dynamic array indexing makes llvmpipe
    // spill the arrays to memory.
    float reach = 3.0 * sigma_d;
    float reach_sq = reach * reach;
    int a = 0;
    int b = 0;
    float t_max = 0.0;
    float t_min = 0.0;
    vec4 c_a = c[0], c_b = c[0], f_a = f[0], f_b = f[0];
    ivec2 offset_a = ivec2(0), offset_b = ivec2(0);
    for (int i = 1; i < 9; ++i) {
        vec4 offset = c[i] - c[0];
        float t = dot(offset, x);
        if (dot(offset, offset) - t * t < reach_sq) {
            if (t > t_max) { t_max = t; a = i; c_a = c[i]; f_a = f[i]; offset_a = OFFSETS[i]; }
            if (t < t_min) { t_min = t; b = i; c_b = c[i]; f_b = f[i]; offset_b = OFFSETS[i]; }
        }
    }
    // The direction's sign is arbitrary: name the extremes in neighbour order (see the twin).
    if (a > b) {
        int first = b; b = a; a = first;
        vec4 colour = c_b; c_b = c_a; c_a = colour;
        vec4 filtered = f_b; f_b = f_a; f_a = filtered;
        ivec2 offset = offset_b; offset_b = offset_a; offset_a = offset;
    }
    // F's change at the extremes, before pure colours replace their F (untouched_factor).
    vec4 moved_ab = max(abs(f_a - c_a), abs(f_b - c_b));
    float moved_extremes = max(max(moved_ab.r, moved_ab.g), max(moved_ab.b, moved_ab.a));
    vec4 span = c_a - c_b;
    float span_sq = dot(span, span);
    float alpha = span_sq > TINY ? clamp(dot(c[0] - c_b, span) / span_sq, 0.0, 1.0) : 0.5;
    vec4 miss = alpha * c_a + (1.0 - alpha) * c_b - c[0];
    float residual = sqrt(dot(miss, miss));
#if BEST_PAIR
    if (residual > BEST_PAIR_MISS * sigma_d) {
        float largest_miss = BEST_PAIR_GAIN * residual;
        BestPair best = BestPair(largest_miss * largest_miss, alpha, a, b);
        float least_span = (BEST_PAIR_SPAN * BEST_PAIR_SPAN) * span_sq;
        // Each pair named with constant indices: an index into c[] that the compiler cannot
        // resolve (a loop it does not unroll) puts c[] in memory for the whole shader.
        try_pair(best, c[0], c[1], c[2], 1, 2, least_span); try_pair(best, c[0], c[1], c[3], 1, 3, least_span);
        try_pair(best, c[0], c[1], c[4], 1, 4, least_span); try_pair(best, c[0], c[1], c[5], 1, 5, least_span);
        try_pair(best, c[0], c[1], c[6], 1, 6, least_span); try_pair(best, c[0], c[1], c[7], 1, 7, least_span);
        try_pair(best, c[0], c[1], c[8], 1, 8, least_span); try_pair(best, c[0], c[2], c[3], 2, 3, least_span);
        try_pair(best, c[0], c[2], c[4], 2, 4, least_span); try_pair(best, c[0], c[2], c[5], 2, 5, least_span);
        try_pair(best, c[0], c[2], c[6], 2, 6, least_span); try_pair(best, c[0], c[2], c[7], 2, 7, least_span);
        try_pair(best, c[0], c[2], c[8], 2, 8, least_span); try_pair(best, c[0], c[3], c[4], 3, 4, least_span);
        try_pair(best, c[0], c[3], c[5], 3, 5, least_span); try_pair(best, c[0], c[3], c[6], 3, 6, least_span);
        try_pair(best, c[0], c[3], c[7], 3, 7, least_span); try_pair(best, c[0], c[3], c[8], 3, 8, least_span);
        try_pair(best, c[0], c[4], c[5], 4, 5, least_span); try_pair(best, c[0], c[4], c[6], 4, 6, least_span);
        try_pair(best, c[0], c[4], c[7], 4, 7, least_span); try_pair(best, c[0], c[4], c[8], 4, 8, least_span);
        try_pair(best, c[0], c[5], c[6], 5, 6, least_span); try_pair(best, c[0], c[5], c[7], 5, 7, least_span);
        try_pair(best, c[0], c[5], c[8], 5, 8, least_span); try_pair(best, c[0], c[6], c[7], 6, 7, least_span);
        try_pair(best, c[0], c[6], c[8], 6, 8, least_span); try_pair(best, c[0], c[7], c[8], 7, 8, least_span);
        if (best.a != a || best.b != b) {
            a = best.a; b = best.b; alpha = best.alpha;
            for (int i = 1; i < 9; ++i) {
                if (i == a) { c_a = c[i]; f_a = f[i]; offset_a = OFFSETS[i]; }
                if (i == b) { c_b = c[i]; f_b = f[i]; offset_b = OFFSETS[i]; }
            }
            residual = sqrt(best.miss_sq);
            // F's change at the extremes, of the pair taken.
            moved_ab = max(abs(f_a - c_a), abs(f_b - c_b));
            moved_extremes = max(max(moved_ab.r, moved_ab.g), max(moved_ab.b, moved_ab.a));
        }
    }
#endif
#if TOWARD_ORIGINAL
    // How far F at the extremes lies from O's colour line between them, before pure colours
    // replace their F (toward_original).
    float off_line = max(off_the_line(f_a, c_a, c_b), off_the_line(f_b, c_a, c_b));
#endif
    // The extremes' offsets as base-3 digits (x and y of a, then of b); jacobi.glsl decodes them.
    float code = float((offset_a.x + 1) + 3 * (offset_a.y + 1) + 9 * (offset_b.x + 1) + 27 * (offset_b.y + 1));
#if PURE_COLOURS
    Extension ext_a = extend_extreme(c_a, c_b, p + offset_a, f_a, size, gate);
    Extension ext_b = extend_extreme(c_b, c_a, p + offset_b, f_b, size, gate);
    if (ext_a.extended || ext_b.extended) {
        vec4 pure_span = ext_a.colour - ext_b.colour;
        float pure_span_sq = dot(pure_span, pure_span);
        alpha = pure_span_sq > TINY ? clamp(dot(c[0] - ext_b.colour, pure_span) / pure_span_sq, 0.0, 1.0) : 0.5;
    }
    if (ext_a.extended) { f_a = ext_a.filtered; code += 81.0; }
    if (ext_b.extended) { f_b = ext_b.filtered; code += 162.0; }
    vec4 contrast_vector = f_a - f_b;
    float contrast = sqrt(dot(contrast_vector, contrast_vector));
#if PURE_GATE
    contrast *= gate;  // the photo keeps the paper's edge strength (fit_pure_colour_model)
#endif
    edge = original_gradient * max(filtered_gradient, contrast);
#endif
    fit.edge = edge;
    float beta = confidence(residual, edge);
#if LOCAL_STRENGTH
    beta *= texelFetch(strength_factor, p, 0).r;
#endif
    if (untouched_span > 0.0 && moved_extremes <= UNTOUCHED_EXTREMES) {
        vec4 moved = abs(f[0] - c[0]);
        float t = clamp(max(max(moved.r, moved.g), max(moved.b, moved.a)) / untouched_span, 0.0, 1.0);
        beta *= t * t * (3.0 - 2.0 * t);
    }
#if TOWARD_ORIGINAL
    // A smoothing filter's drawn edges move towards O by the gate of drawn content, last
    // (toward_original in aarecovery/spec/blend_model.py).
    // Only where F kept the extremes on O's colour line (KEPT_EXTREMES): a colour it changed is
    // not O's; along the line is what a smoothing filter moves them.
    float g = (edge > 0.0 && off_line <= KEPT_EXTREMES) ? toward_weight(p, size) : 0.0;
    beta = (1.0 - g) * beta;
    vec4 data = (1.0 - beta) * f[0] + g * (c[0] - f[0]);  // exactly F where F is O
#else
    vec4 data = (1.0 - beta) * f[0];
#endif
    fit.model = vec4(alpha, beta, code, residual);
    fit.first_iterate = beta * (alpha * f_a + (1.0 - alpha) * f_b) + data;
#if PURE_COLOURS
    // Exactly F where beta (and g) are 0, as jacobi.glsl needs.
    vec4 fixed_share = vec4(0.0);
    if (ext_a.extended) fixed_share += alpha * ext_a.filtered;
    if (ext_b.extended) fixed_share += (1.0 - alpha) * ext_b.filtered;
    fit.jacobi_constant = beta * fixed_share + data;
#elif TOWARD_ORIGINAL
    fit.jacobi_constant = data;
#endif
    // Where beta is 0 a step gathers nothing and gives its constant (or F): F itself unless
    // towards O or a pure colour moved it.
#if JACOBI_CONSTANT
    fit.live = beta != 0.0 || any(notEqual(fit.jacobi_constant, f[0]));
#else
    fit.live = beta != 0.0;
#endif
    return fit;
}
