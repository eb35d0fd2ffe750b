// The executor of the tasks library: jobs run here or through their bytes give the same
// results, a job set up differently elsewhere is refused, errors reach the caller.
#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>

#include "pdamp/base/executor.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "tasks/executor_support.hpp"

using namespace pdamp;

namespace {

surrogate::FieldPoint point(std::size_t k) {
  surrogate::FieldPoint p;
  p.eta_star = 0.1 * static_cast<double>(k) + 1.0 / 3.0;  // not exact in binary: a round trip must keep every bit
  p.eta_star_stderr = k % 2 ? NAN : 1e-300;
  p.e_diss_j = -0.0;
  p.motion_mode = "rolling_collect_and_collide\n" + std::to_string(k);
  p.status = k % 3 ? surrogate::PointStatus::kOk : surrogate::PointStatus::kFailed;
  return p;
}

}  // namespace

// Reference: the jobs computed here. Through their bytes (CBOR of the JSON form) every
// double must come back bit for bit and NaN as NaN (FieldPoint::operator== treats NaN as
// equal), so a sweep spread over processes equals the serial one.
TEST_CASE("jobs run through their bytes equal the jobs run here", "[tasks]") {
  test::BytesExecutor elsewhere;
  const auto remote = base::run_jobs<surrogate::FieldPoint>(elsewhere, 7, true, point);
  const auto local = base::run_jobs<surrogate::FieldPoint>(base::local_executor(), 7, false, point);
  CHECK(elsewhere.jobs_elsewhere == 7);
  REQUIRE(remote.size() == 7);
  for (std::size_t k = 0; k < 7; ++k) {
    CHECK(remote[k] == local[k]);
    CHECK(remote[k] == point(k));
    CHECK(std::signbit(remote[k].e_diss_j));
  }
}

TEST_CASE("a job whose inputs differ in the process that runs it is refused", "[tasks]") {
  const auto job = [](std::size_t k) { return static_cast<double>(k); };
  const auto design = [](std::size_t k) { return 1000.0 + static_cast<double>(k); };
  test::BytesExecutor same;
  CHECK(base::Jobs<double>(same, job, design)(3) == 3.0);
  test::BytesExecutor other(true);
  base::Jobs<double> jobs(other, job, design);
  CHECK_THROWS_WITH(jobs(3), Catch::Contains("set up differently"));
}

TEST_CASE("an exception in a concurrent job reaches the caller, the first in order", "[tasks]") {
  CHECK_THROWS_WITH(base::for_each_concurrently(4, true,
                                                 [](std::size_t k) {
                                                   if (k >= 2) throw std::runtime_error("job " + std::to_string(k));
                                                 }),
                    "job 2");
  std::vector<int> ran(5, 0);
  base::for_each_concurrently(5, false, [&](std::size_t k) { ran[k] = 1; });
  CHECK(std::count(ran.begin(), ran.end(), 1) == 5);
}

TEST_CASE("two jobs run at once where two cores or two processes are", "[tasks]") {
  test::BytesExecutor two_processes;
  CHECK(base::parallel_jobs(two_processes, 2) == (std::thread::hardware_concurrency() >= 2));
  CHECK_FALSE(base::parallel_jobs(base::local_executor(), 1));
}
