// Text from files (names, sidecar values, library messages) made safe for a terminal before it is
// printed: control characters, DEL, backslashes and non-ASCII bytes become \xNN, and long text is cut.
#pragma once
#include <string>

namespace pmr {

std::string printable_text(const std::string& text, size_t limit = 120);

// The length of the UTF-8 sequence at text[i] when it encodes a character a terminal prints as
// text: printable ASCII, or a well-formed multi-byte sequence of a code point from U+00A0 up (the C1
// controls U+0080 to U+009F, U+009B being CSI, are excluded, as are the bidirectional formatting
// characters (U+061C, U+200E, U+200F, U+202A to U+202E, U+2066 to U+2069), overlong forms and surrogates).
// 0 for anything else (controls, DEL, stray or truncated bytes).
size_t printable_utf8_length(const std::string& text, size_t i);

// A whole message for the terminal (errors, warnings): printable ASCII and well-formed UTF-8 kept
// (file names in other scripts stay readable), newlines and tabs become spaces, every other byte
// (C0 and C1 controls, DEL, malformed UTF-8) \xNN. Nothing is cut.
std::string terminal_text(const std::string& text);

}  // namespace pmr
