#pragma once
// Private to tethash::meshing: OpenMP pragmas that vanish in a build without OpenMP.
#ifdef _OPENMP
#define TETHASH_OMP(directive) _Pragma(directive)
#else
#define TETHASH_OMP(directive)
#endif
