// A symmetric n x n matrix on the wire as its upper triangle, row by row:
// entries (i, j) with j >= i, n (n + 1) / 2 of them, half the bytes of the
// square. The FEM sends its compliance block so (idl/fahr
// deformation_state.idl); the haptic side unpacks it.
#pragma once

#include <cstddef>

namespace fahr::common {

constexpr std::size_t packed_upper_size(std::size_t n) {
  return n * (n + 1) / 2;
}

// Where (i, j), i <= j < n, lies in the packed upper triangle.
constexpr std::size_t packed_upper_index(std::size_t n, std::size_t i, std::size_t j) {
  return i * n - i * (i - 1) / 2 + (j - i);
}

// Packs the symmetric part (M + M^T) / 2 of the row-major n x n matrix
// `full` into packed[0, packed_upper_size(n)).
template <class In, class Out>
void pack_upper(const In* full, std::size_t n, Out* packed) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i; j < n; ++j) {
      packed[k++] = static_cast<Out>(
          0.5 * (static_cast<double>(full[i * n + j]) + static_cast<double>(full[j * n + i])));
    }
  }
}

// Writes the whole n x n matrix a packed upper triangle stands for into the
// rows of a larger row-major matrix: element (r, c) goes to out[r * stride + c].
template <class T>
void unpack_upper(const T* packed, std::size_t n, T* out, std::size_t stride) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i; j < n; ++j, ++k) {
      out[i * stride + j] = packed[k];
      out[j * stride + i] = packed[k];
    }
  }
}

}  // namespace fahr::common
