// Random numbers for ray generation.
//   thesis_hash : R(s) = fract(sin(s . (12.9898, 78.233)) * 43758.5453) (seed 000, 2.3.4)
//   pcg_hash    : PCG output permutation as a hash (Jarzynski & Olano, JCGT 9(3), 2020),
//                 well distributed and the same on every GPU
//   hammersley  : point i of an n-point Hammersley set, (i/n, radical inverse of i)

float thesis_hash(vec2 s) {
    return fract(sin(dot(s, vec2(12.9898, 78.233))) * 43758.5453);
}

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A uniform number in [0, 1) from the top 24 bits.
float unit_float(uint x) {
    return float(x >> 8u) * (1.0 / 16777216.0);
}

vec2 hammersley(uint i, uint n) {
    return vec2(float(i) / float(n), float(bitfieldReverse(i)) * 2.3283064365386963e-10);
}
