// aloft: the command line of the Aloft mobile simulator. One subcommand per file (cmd_*.cpp); this file
// parses the command line and turns every failure into a message and an exit code:
//   0 success, 1 bad input (aloft::InputError, unwritable output), 2 wrong usage (CLI11's message),
//   3 the simulation failed.

#include <cstdio>
#include <exception>
#include <map>
#include <new>
#include <utility>

#include "aloft/error.hpp"
#include "common.hpp"

#ifndef ALOFT_VERSION
#define ALOFT_VERSION "unknown"
#endif

int main(int argc, char** argv) {
  using namespace aloft::cli;
  CLI::App app{"Aloft: simulate hanging mobiles (Calder-style) from their mobile files.", "aloft"};
  app.set_version_flag("--version", std::string("aloft ") + ALOFT_VERSION);
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  aloft generate --components 127 --seed 3 --out random.json\n"
      "  aloft inspect random.json\n"
      "  aloft simulate random.json --duration 10 --out trajectory.csv\n"
      "  aloft bench\n"
      "\n"
      "Run 'aloft <command> --help' for the options of each command.\n"
      "Exit codes: 0 success, 1 bad input file or unwritable output, 2 wrong usage, 3 the simulation failed.\n");

  std::map<const CLI::App*, Runner> runners;
  try {
    for (const CommandEntry& command : registered_commands()) {
      Runner run = command.add(app);
      runners[app.get_subcommand(command.name)] = std::move(run);
    }
  } catch (const std::exception& e) {
    print_error(std::string("internal: ") + e.what());
    return kExitInput;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }

  try {
    for (const auto& [sub, run] : runners)
      if (sub->parsed()) return run();
    return kExitUsage;  // unreachable: a subcommand is required
  } catch (const aloft::InputError& e) {
    print_error(e.what());
  } catch (const Failure& e) {
    print_error(e.what());
  } catch (const std::bad_alloc&) {
    print_error("out of memory");
  } catch (const std::exception& e) {
    print_error(e.what());
  }
  return kExitInput;
}
