// The table of error classes and exit codes (errors.hpp).
#include "errors.hpp"

#include <new>
#include <stdexcept>

#include "pdamp/base/executor.hpp"

namespace pdamp::cli {

ErrorOutcome classify_error(const std::exception_ptr& error, const std::string& command) {
  try {
    std::rethrow_exception(error);
  } catch (const InputError& e) {
    return {kExitBadInput, e.what()};
  } catch (const std::invalid_argument& e) {
    return {kExitBadInput, "pdamp " + command + ": " + e.what()};
  } catch (const NumericalError& e) {
    return {kExitNumerical, e.what()};
  } catch (const Interrupted& e) {  // the OutputDir's destructor removed what was staged
    return {kExitOther, e.what(), e.signal_number()};
  } catch (const base::JobsServedElsewhere&) {  // an MPI worker: rank 0 reports
    return {kExitOk, ""};
  } catch (const std::bad_alloc&) {
    return {kExitOther, "out of memory (see the run's estimate on stderr; reduce the case's sizes)"};
  } catch (const std::exception& e) {
    return {kExitOther, e.what()};
  } catch (...) {
    return {kExitOther, "an unknown exception"};
  }
}

}  // namespace pdamp::cli
