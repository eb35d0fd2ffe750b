// placeholder: filled by the structure issue
#include <benchmark/benchmark.h>
BENCHMARK_MAIN();
