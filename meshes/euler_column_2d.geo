// Euler column of seed §2.3.1: cantilever of length L = 1 m along +y,
// clamped at the base, 10 equal two-node beam elements.
L = 1.0;
n = 10;
Point(1) = {0, 0, 0};
Point(2) = {0, L, 0};
Line(1) = {1, 2};
Transfinite Curve{1} = n + 1;
Physical Curve("column") = {1};
Physical Point("base") = {1};
Physical Point("tip") = {2};
