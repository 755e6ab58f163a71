// The run-time choice of the fused block kernels' ISA variant, written once for the three
// papers. Each paper's fused kernels are compiled once per variant (kernels/CMakeLists.txt),
// each time inside the namespace HAIRBENCH_ISA_VARIANT names: the portable `baseline`
// and, where the compiler accepts -march=x86-64-v4, `x86_64_v4` (AVX-512). Both give the
// same bits (FMA contraction is off), so the choice changes speed only.
#pragma once

#include <type_traits>

namespace hairbench::kernels::simd {

enum class Isa { Baseline, X86_64_V4 };

// The best variant this build has and this CPU runs (AVX-512 F, BW, DQ and VL for
// x86-64-v4), decided once per process.
Isa runtime_isa();
const char* isa_name(Isa isa);

// A family's entry point for the running CPU, from its variants' entry points; `v4` is
// null where the build has no x86-64-v4 variant (HAIRBENCH_V4_ENTRY).
template <class Entry>
Entry select(Entry (*baseline)(), std::type_identity_t<Entry (*)()> v4) {
  return v4 != nullptr && runtime_isa() == Isa::X86_64_V4 ? v4() : baseline();
}

}  // namespace hairbench::kernels::simd

// The x86-64-v4 variant's `fn` where the build has it, else null: lets a family name its
// v4 entry point without an #ifdef of its own.
#ifdef HAIRBENCH_SOA_V4
#define HAIRBENCH_V4_ENTRY(fn) (&x86_64_v4::fn)
#else
#define HAIRBENCH_V4_ENTRY(fn) nullptr
#endif
