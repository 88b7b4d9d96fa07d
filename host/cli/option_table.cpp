#include "cli/option_table.h"

namespace pmr {

std::string option_help_entry(const char* name, const char* alias, const char* arg, const std::string& help,
                              size_t column) {
  const std::string value = arg ? std::string(" ") + arg : "";
  std::string line = std::string("  ") + name + value + (alias ? std::string(", ") + alias + value : "");
  line += line.size() < column ? std::string(column - line.size(), ' ') : "  ";
  for (char c : help) line += c == '\n' ? "\n" + std::string(column, ' ') : std::string(1, c);
  return line + "\n";
}

}  // namespace pmr
