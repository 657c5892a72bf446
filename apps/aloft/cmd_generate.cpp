// aloft generate: a random balanced mobile (aloft::generate_mobile) as a mobile file.

#include <cstdio>
#include <memory>

#include "aloft/generate.hpp"
#include "common.hpp"

namespace aloft::cli {

Runner add_generate(CLI::App& app) {
  struct Options {
    int components = 15;
    unsigned seed = 1;
    double total_mass = 1.0;
    std::string out;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "generate",
      "Write a random balanced mobile file");
  sub->add_option("-n,--components", o->components, "Number of components, the fixed hook included (>= 2)")
      ->type_name("N")
      ->required()
      ->check(integer_in(2, 1 << 24));
  sub->add_option("-s,--seed", o->seed, "Random seed (0 to 4294967295)")
      ->type_name("S")
      ->capture_default_str()
      ->check(integer_in(0, 4294967295LL));
  sub->add_option("-m,--total-mass", o->total_mass,
                  "Total mass of the moving components (kg, from 1e-6 to 1e6: what a mobile file may say)")
      ->type_name("KG")
      ->capture_default_str()
      ->check(number_in(kLightestMobile, kHeaviestMobile));
  sub->add_option("-o,--out", o->out, "Output file (default: standard output)")->type_name("FILE");
  sub->footer(
      "The mobile: a fixed hook, a binary tree of wire bars, plates and balls at the leaves, balance\n"
      "mode \"mass\" (so the designed pose hangs still). The same options give the same file on every\n"
      "machine.\n"
      "\n"
      "Examples:\n"
      "  aloft generate --components 15 --seed 1                  # to standard output\n"
      "  aloft generate --components 8191 --seed 7 --out big.json\n"
      "  aloft generate -n 127 -s 2 --total-mass 0.5 -o medium.json\n");
  return [o] {
    GenerateOptions g;
    g.components = o->components;
    g.seed = o->seed;
    g.total_mass = o->total_mass;
    const std::string text = generate_mobile(g);
    if (o->out.empty()) {
      std::fwrite(text.data(), 1, text.size(), stdout);
      if (std::fflush(stdout) != 0) throw Failure("cannot write to standard output");
    } else {
      write_file(o->out, text);
    }
    return kExitOk;
  };
}

static const CommandRegistration registration{"generate", 10, add_generate};

}  // namespace aloft::cli
