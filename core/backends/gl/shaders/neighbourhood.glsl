// The 3x3 neighbourhood every pass reads. Twin: aarecovery/spec/neighbourhood.py.

// Neighbourhood order of NEIGHBOUR_OFFSETS (x = column, y = row): centre, N, W, E, S, NW, NE, SW, SE.
const ivec2 OFFSETS[9] = ivec2[9](
    ivec2(0, 0), ivec2(0, -1), ivec2(-1, 0), ivec2(1, 0), ivec2(0, 1),
    ivec2(-1, -1), ivec2(1, -1), ivec2(-1, 1), ivec2(1, 1));

// Borders replicate edge pixels.
ivec2 clamp_to_image(ivec2 p, ivec2 size) {
    return clamp(p, ivec2(0), size - 1);
}
