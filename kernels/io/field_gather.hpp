#pragma once
// A cell field's owned points gathered onto rank 0 as one global array (x fastest, then
// y, then z), for output and for comparisons in tests. Every block must have the same
// size (an even decomposition, as CartDecomposition makes). Not for full-size cases:
// rank 0 holds the whole field.
#include <vector>

#include "field.hpp"

namespace efsi {

// Collective over dec.comm(); rank 0 receives the field, the others an empty vector.
std::vector<double> gather_global(const Field& f, const CartDecomposition& dec);

}  // namespace efsi
