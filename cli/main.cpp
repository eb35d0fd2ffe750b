// pdamp command-line front end: dispatch to a subcommand, map errors to exit codes.
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "errors.hpp"

namespace {

void print_overview() {
  std::cout << "pdamp " << "0.1.0" << ": design and optimisation of particle dampers\n\n"
            << "usage: pdamp <command> [options]   (pdamp <command> --help for its options)\n\ncommands:\n";
  for (const auto& command : pdamp::cli::commands()) {
    std::string name = "  " + command.spec.name;
    name.resize(12, ' ');
    std::cout << name << command.spec.summary.substr(0, command.spec.summary.find('\n')) << "\n";
  }
  std::cout << "\nUnits are SI (m, s, kg, Hz, Pa). Exit codes: 0 success, 1 other failure,\n"
               "2 bad input, 3 numerical failure at run time.\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pdamp::cli;
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    print_overview();
    return args.empty() ? kExitBadInput : kExitOk;
  }
  try {
    for (const auto& command : commands()) {
      if (command.spec.name != args[0]) continue;
      const ParsedArgs parsed(command.spec, std::vector<std::string>(args.begin() + 1, args.end()));
      if (parsed.help_requested()) {
        std::cout << help_text(command.spec);
        return kExitOk;
      }
      return command.run(parsed);
    }
    throw InputError(args[0], "", "unknown command (see pdamp --help)");
  } catch (const InputError& e) {
    std::cerr << "pdamp: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "pdamp: error: " << args[0] << ": " << e.what() << "\n";
    return kExitBadInput;
  } catch (const NumericalError& e) {
    std::cerr << "pdamp: error: " << e.what() << "\n";
    return kExitNumerical;
  } catch (const std::exception& e) {
    std::cerr << "pdamp: error: " << e.what() << "\n";
    return kExitOther;
  }
}
