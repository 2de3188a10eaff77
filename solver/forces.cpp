// Forces and end paths are header templates (forces.hpp); this file instantiates them once for 2D
// and 3D so that every member compiles in both dimensions.
#include "forces.hpp"

namespace chainsim {

template class Gravity<2>;
template class Gravity<3>;
template class Drag<2>;
template class Drag<3>;
template class EndLoad<2>;
template class EndLoad<3>;
template class FixedPoint<2>;
template class FixedPoint<3>;
template class HarmonicPath<2>;
template class HarmonicPath<3>;
template class LinearPath<2>;
template class LinearPath<3>;

}  // namespace chainsim
