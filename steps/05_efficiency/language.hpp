// The choice of language, measured within one: the same small kernel (the nearest
// ray/sphere hit of each ray) compiled several times with different compiler flags, in
// float and in double. CMakeLists.txt compiles experiments/language_kernel.cpp once per
// variant, each copy in its own namespace and with only its own flags.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace boxes::language {

// Spheres as (cx, cy, cz, r), rays as (ox, oy, oz, dx, dy, dz) with |d| = 1; writes the
// nearest t > 0 of each ray into t, +inf for a miss.
template <typename T>
using NearestFn = void (*)(const T* spheres, size_t sphereCount, const T* rays, size_t rayCount,
                           T* t);

struct KernelVariant {
    std::string name;   // "O2", the reference
    std::string flags;  // the compile options it was built with, as given to the compiler
    NearestFn<float> nearestFloat;
    NearestFn<double> nearestDouble;
};

// Every variant of this build, -O0 first; the -march=native ones only where the compiler
// takes the flag.
const std::vector<KernelVariant>& kernelVariants();
// The reference: the variant named "O2".
const KernelVariant& referenceVariant();

// What each copy of the kernel defines, in namespace boxes::language::NAME.
#define BOXES_LANGUAGE_KERNEL_DECLARATIONS                                            \
    const char* flags();                                                              \
    void nearestFloat(const float* spheres, size_t sphereCount, const float* rays,    \
                      size_t rayCount, float* t);                                     \
    void nearestDouble(const double* spheres, size_t sphereCount, const double* rays, \
                       size_t rayCount, double* t);

}  // namespace boxes::language
