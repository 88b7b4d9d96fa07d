// A command's options as one table (pmr render, pmr bench): the parser and --help are both made from
// it, so an option cannot be parsed without being listed, or listed under another spelling.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "pmr/error.h"

namespace pmr {

// One option of a command whose options are gathered in an `Options`.
template <typename Options>
struct Option {
  const char* name;   // "--out"
  const char* alias;  // "-o", or nullptr
  const char* arg;    // the value's placeholder in --help ("DIR"); nullptr for a flag
  std::string help;   // the description, '\n' between its lines; empty: not listed (see the entry)
  // applies the option: `value` is empty for a flag, `name` the option's name for messages
  void (*set)(Options& o, const std::string& value, const std::string& name);
  std::string (*more_help)() = nullptr;  // lines --help prints verbatim after the description
};

// Options listed together in --help, after their heading (verbatim lines; nullptr: none).
template <typename Options>
struct OptionSection {
  const char* heading;
  std::vector<Option<Options>> options;
};

// How a command's table reads and lists: its name in messages ("render": "see pmr render --help"),
// the column where --help's descriptions start, and what a bare argument (no leading '-') is.
template <typename Options>
struct OptionTable {
  const char* command;
  size_t help_column;
  std::vector<const OptionSection<Options>*> sections;
  void (*positional)(Options& o, const std::string& arg);
};

// One --help entry: "--out DIR, -o DIR" padded to `column` (or two spaces after a longer one), the
// description's further lines indented to that column.
std::string option_help_entry(const char* name, const char* alias, const char* arg, const std::string& help,
                              size_t column);

// Applies `args` to `o` by the table. Throws pmr::Error on an unknown option or a missing value, and
// whatever an option's or the positional argument's setter throws.
template <typename Options>
void parse_by_table(const OptionTable<Options>& table, Options& o, const std::vector<std::string>& args) {
  const std::string see = std::string(" (see pmr ") + table.command + " --help)";
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const Option<Options>* found = nullptr;
    for (const OptionSection<Options>* s : table.sections)
      for (const Option<Options>& opt : s->options)
        if (!found && (a == opt.name || (opt.alias && a == opt.alias))) found = &opt;
    if (found) {
      if (found->arg && i + 1 >= args.size()) throw Error("option " + a + " needs a value" + see);
      found->set(o, found->arg ? args[++i] : std::string(), found->name);
    } else if (!a.empty() && a[0] == '-') {
      throw Error("unknown option " + a + see);
    } else {
      table.positional(o, a);
    }
  }
}

// The listed options of every section, under their headings.
template <typename Options>
std::string options_help(const OptionTable<Options>& table) {
  std::string out;
  for (const OptionSection<Options>* section : table.sections) {
    if (section->heading) out += std::string(section->heading) + "\n";
    for (const Option<Options>& opt : section->options)
      if (!opt.help.empty())
        out += option_help_entry(opt.name, opt.alias, opt.arg, opt.help, table.help_column) +
               (opt.more_help ? opt.more_help() : "");
  }
  return out;
}

}  // namespace pmr
