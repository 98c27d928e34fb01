// The Sobel magnitude of a working-space neighbourhood. Twin: sobel_magnitude in
// aarecovery/spec/sobel.py, which explains the scale (divided by 8).

float sobel_magnitude(vec4 v[9]) {
    // v is in OFFSETS order: 1 N, 2 W, 3 E, 4 S, 5 NW, 6 NE, 7 SW, 8 SE.
    // Differences first, so that a flat neighbourhood gives exactly 0 (see the NumPy twin).
    vec4 gx = ((v[6] - v[5]) + 2.0 * (v[3] - v[2]) + (v[8] - v[7])) * 0.125;
    vec4 gy = ((v[7] - v[5]) + 2.0 * (v[4] - v[1]) + (v[8] - v[6])) * 0.125;
    return sqrt(dot(gx, gx) + dot(gy, gy));
}

// How far the centre stands out from the mean of an opposite pair of its neighbours, the
// largest over the four pairs. Twin: ridge_magnitude in aarecovery/spec/sobel.py.
float ridge_magnitude(vec4 v[9]) {
    vec4 ns = ((v[0] - v[1]) + (v[0] - v[4])) * 0.5;
    vec4 we = ((v[0] - v[2]) + (v[0] - v[3])) * 0.5;
    vec4 diagonal = ((v[0] - v[5]) + (v[0] - v[8])) * 0.5;
    vec4 antidiagonal = ((v[0] - v[6]) + (v[0] - v[7])) * 0.5;
    return sqrt(max(max(dot(ns, ns), dot(we, we)), max(dot(diagonal, diagonal), dot(antidiagonal, antidiagonal))));
}
