// Eigen kernels for the serial N_Vector operations that dominate an explicit step, and the
// element-wise ones of an implicit step (constants, error weights).
//
// The serial N_Vector of the SUNDIALS package is compiled for a generic CPU and its loops run one
// scalar at a time (a reduction is one long chain of dependent additions). A profile of erk4 on a
// 201-link hanging chain put N_VLinearCombination_Serial (the stage sums) and N_VWSqrSumLocal_Serial
// (the error norms) at a third of the run. use_eigen_kernels() replaces those operations in the
// vector's operation table (SUNDIALS copies the table into every clone) by the same arithmetic on
// Eigen maps, which Eigen vectorizes and reduces with several partial sums. Only the arithmetic is
// Eigen's; what each operation means is SUNDIALS's (sundials_nvector.h).
#pragma once

#include <nvector/nvector_serial.h>

namespace chainsim {

/// Replaces the hot operations of a serial N_Vector (and of its future clones) by Eigen kernels.
void use_eigen_kernels(N_Vector v);

}  // namespace chainsim
