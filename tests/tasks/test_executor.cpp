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
  const auto design = [](std::size_t k) { return "slabs 3 " + std::to_string(k) + "; softening 0.001"; };
  test::BytesExecutor same;
  CHECK(base::Jobs<double>(same, job, design)(3) == 3.0);
  test::BytesExecutor other(true);
  base::Jobs<double> jobs(other, job, design);
  CHECK_THROWS_WITH(jobs(3), Catch::Contains("set up differently"));
  CHECK_THROWS_WITH(base::run_jobs<double>(other, 2, false, job, nullptr, design), Catch::Contains("set up differently"));
}

// Reference: FNV-1a's published 64-bit test vectors; texts that differ in one character (a
// design of 10 slabs against one of 1 and 0) differ in their fingerprints.
TEST_CASE("a job's fingerprint is the FNV-1a hash of the text naming its inputs", "[tasks]") {
  CHECK(base::fingerprint("") == 0xcbf29ce484222325ULL);
  CHECK(base::fingerprint("a") == 0xaf63dc4c8601ec8cULL);
  CHECK(base::fingerprint("foobar") == 0x85944171f73967e8ULL);
  CHECK(base::fingerprint("10 0 softening 0.001") != base::fingerprint("1 00 softening 0.001"));
}

namespace {

/// A task of two batches, the second set up from the first's results (as a design loop's
/// verification follows its calibration and optimisation).
std::vector<double> two_batches(base::Executor& executor) {
  const auto inputs = [](std::size_t k) { return "job " + std::to_string(k); };
  const auto first = base::run_jobs<double>(
      executor, 3, true, [](std::size_t k) { return 1.0 / 3.0 + static_cast<double>(k); }, nullptr, inputs);
  double sum = 0.0;
  for (const double x : first) sum += x;
  auto second = base::run_jobs<double>(
      executor, 4, true, [&](std::size_t k) { return sum / 7.0 * static_cast<double>(k); }, nullptr,
      [&](std::size_t k) { return "after " + std::to_string(sum) + ", job " + std::to_string(k); });
  second.insert(second.end(), first.begin(), first.end());
  return second;
}

}  // namespace

// Reference: the same task run here. Through the bytes each batch's jobs come back bit for
// bit; the process that served them gets each batch's results at its end and goes on with
// the task to the next batch, ending with the same results.
TEST_CASE("two batches in a row through bytes give the serial results on both processes", "[tasks]") {
  const auto here = two_batches(base::local_executor());
  test::BytesExecutor elsewhere;
  CHECK(two_batches(elsewhere) == here);
  CHECK(elsewhere.jobs_elsewhere == 7);
  CHECK(elsewhere.batches == 2);
  REQUIRE(elsewhere.ended.size() == 2);
  for (const auto& end : elsewhere.ended) CHECK((end && *end));  // each ended with its results

  test::ServingExecutor served(elsewhere.ended);
  CHECK(two_batches(served) == here);
  CHECK(served.batches() == 2);
  CHECK_FALSE(served.primary());

  // A batch of another size than the primary's: the processes differ.
  test::ServingExecutor other(elsewhere.ended);
  CHECK_THROWS_WITH(base::run_jobs<double>(other, 5, false, [](std::size_t) { return 0.0; }),
                    Catch::Contains("the processes differ"));
}

// A sweep's results are the primary's alone (some from its log): its batch ends without
// results, and the process that served it ends its task; so does a task that runs on the
// primary alone.
TEST_CASE("a sweep's batch ends without results and the serving process ends its task", "[tasks]") {
  test::BytesExecutor elsewhere;
  {
    base::Jobs<surrogate::FieldPoint> jobs(elsewhere, point);
    CHECK(jobs(2) == point(2));
    jobs.end();
  }
  {
    base::Jobs<surrogate::FieldPoint> unended(elsewhere, point);  // an exception on the way: ends as a sweep
  }
  REQUIRE(elsewhere.ended.size() == 2);
  for (const auto& end : elsewhere.ended) CHECK((end && !*end));
  test::ServingExecutor served(elsewhere.ended);
  CHECK_THROWS_AS(base::Jobs<surrogate::FieldPoint>(served, point), base::JobsServedElsewhere);
  CHECK_THROWS_AS(served.primary_only(), base::JobsServedElsewhere);
  CHECK_NOTHROW(elsewhere.primary_only());
  CHECK_NOTHROW(base::local_executor().primary_only());
  CHECK(base::local_executor().primary());
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
