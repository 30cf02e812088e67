#pragma once
// cpu_affinity.hpp: let the calling process run on every online core.
//
// mpirun binds each rank to one core (OpenMPI's default for two ranks or
// fewer). Where rank 0 does the work while the other ranks sleep (the FEM
// solve, and a command's work after its FEM references), its threads should
// use every core.

namespace puncture::fem {

/// Widens the calling process's CPU affinity to every online core (Linux;
/// elsewhere nothing). Best effort: where the system refuses, the binding
/// stays and the threads share the bound core.
void widen_cpu_affinity();

}  // namespace puncture::fem
