// A run-time count in a small range dispatched to code compiled for each count: a narrow
// supernode's width, a batch's vectors per row, a batch's frames. Used by the solver's and the
// right-hand side's kernel variants and by the parallel solve's row copies.
//
// Everything here is in an anonymous namespace and only standard headers are included, so the
// kernel variants, each built with its own instruction set, can include it without sharing a
// definition with external linkage at link time.
#pragma once

#include <utility>

namespace deform {
namespace {

// A count fixed at compile time.
template <int kCount>
struct Count {
  static constexpr int value = kCount;
};

template <typename Run, int... kCounts>
inline void WithCountOf(int count, Run&& run, std::integer_sequence<int, kCounts...>) {
  ((count == kCounts + 1 ? run(Count<kCounts + 1>()) : void()), ...);
}

// Calls run(Count<count>()) for `count` in [1, kMax], so that what `run` calls is compiled for
// every count and its loops over the count unroll; does nothing for another count.
template <int kMax, typename Run>
inline void WithCount(int count, Run&& run) {
  WithCountOf(count, run, std::make_integer_sequence<int, kMax>());
}

}  // namespace
}  // namespace deform
