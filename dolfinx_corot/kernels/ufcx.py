"""The ufcx ``tabulate_tensor`` signature shared by every element kernel handed to DOLFINx.

``void(double* A, const double* w, const double* c, const double* coordinate_dofs,
const int* entity_local_index, const uint8_t* quadrature_permutation)``: A the
element tensor (row-major), w the packed coefficients, c the constants,
coordinate_dofs the cell's node coordinates (always 3 per node).
"""
from numba import types

signature = types.void(types.CPointer(types.double), types.CPointer(types.double),
                       types.CPointer(types.double), types.CPointer(types.double),
                       types.CPointer(types.int32), types.CPointer(types.uint8))
