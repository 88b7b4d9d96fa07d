// Text from files (names, sidecar values, library messages) made safe for a terminal before it is
// printed: control characters, DEL, backslashes and non-ASCII bytes become \xNN, and long text is cut.
#pragma once
#include <string>

namespace pmr {

std::string printable_text(const std::string& text, size_t limit = 120);

}  // namespace pmr
