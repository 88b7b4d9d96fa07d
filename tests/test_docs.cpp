// The documentation ships with the code (issue 20): the README and docs/ link only files of the source
// tree, their section links land on headings that exist, the code's "DESIGN N" citations name sections
// that docs/DESIGN.md has, and `pmr render --help` points to the docs.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = PMR_SOURCE_DIR;

// Markdown files a user of the source tree reads: the README and everything under docs/.
std::vector<fs::path> markdown_files() {
  std::vector<fs::path> files = {kSource / "README.md"};
  for (const auto& e : fs::recursive_directory_iterator(kSource / "docs"))
    if (e.is_regular_file() && e.path().extension() == ".md") files.push_back(e.path());
  return files;
}

// GitHub's anchor for a heading: lower case, punctuation other than '-' and '_' dropped, spaces to '-'.
std::string slug(const std::string& heading) {
  std::string s;
  for (unsigned char c : heading) {
    if (std::isalnum(c) || c == '-' || c == '_') s += char(std::tolower(c));
    else if (c == ' ') s += '-';
  }
  return s;
}

// The anchors of a Markdown file's headings (outside fenced code blocks).
std::set<std::string> anchors(const fs::path& file) {
  std::set<std::string> out;
  std::istringstream in(test::read_file(file.string()));
  bool fenced = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    if (fenced || line.empty() || line[0] != '#') continue;
    const size_t text = line.find_first_not_of('#');
    if (text == std::string::npos || line[text] != ' ') continue;
    out.insert(slug(line.substr(text + 1)));
  }
  return out;
}

TEST(Docs, LinksStayInsideTheSourceTreeAndLandOnHeadings) {
  const std::regex link(R"(\]\(([^)\s]+)\))");
  size_t checked = 0, with_anchor = 0;
  for (const fs::path& md : markdown_files()) {
    const std::string text = test::read_file(md.string());
    const std::string name = fs::relative(md, kSource).string();
    // the development contract lives outside the repository: users never have it
    EXPECT_EQ(text.find("../shared"), std::string::npos) << name << " refers to ../shared";
    EXPECT_EQ(text.find("DESIGN section"), std::string::npos) << name << " cites the contract by section";
    for (std::sregex_iterator it(text.begin(), text.end(), link), end; it != end; ++it) {
      const std::string target = (*it)[1];
      if (target.rfind("http://", 0) == 0 || target.rfind("https://", 0) == 0 || target.rfind("mailto:", 0) == 0)
        continue;
      const size_t hash = target.find('#');
      const std::string file = target.substr(0, hash);
      const fs::path resolved = file.empty() ? md : fs::weakly_canonical(md.parent_path() / file);
      ++checked;
      EXPECT_TRUE(fs::exists(resolved)) << name << " links " << target << ", which does not exist";
      const std::string rel = fs::relative(resolved, fs::weakly_canonical(kSource)).string();
      EXPECT_FALSE(rel.rfind("..", 0) == 0) << name << " links " << target << ", outside the source tree";
      if (hash != std::string::npos && fs::exists(resolved) && resolved.extension() == ".md") {
        ++with_anchor;
        EXPECT_TRUE(anchors(resolved).count(target.substr(hash + 1)))
            << name << " links " << target << ": no such heading in " << rel;
      }
    }
  }
  EXPECT_GT(checked, 20u) << "the README and docs/ link each other";
  EXPECT_GT(with_anchor, 5u) << "section links were found and checked";
}

TEST(Docs, DesignHasEverySectionTheCodeCites) {
  // "DESIGN section 5", "DESIGN sections 2 and 3", "DESIGN 4b"
  const std::regex citation(R"(DESIGN(?: sections?)? (\d[a-z]?)((?:(?:, | and )\d[a-z]?)*))");
  const std::regex number(R"(\d[a-z]?)");
  std::set<std::string> cited;
  for (const char* dir : {"cl", "host", "include", "tests"})
    for (const auto& e : fs::recursive_directory_iterator(kSource / dir)) {
      const std::string ext = e.path().extension().string();
      if (!e.is_regular_file() || (ext != ".cpp" && ext != ".h" && ext != ".cl")) continue;
      if (e.path().filename() == "test_docs.cpp") continue;  // this file's own examples
      const std::string text = test::read_file(e.path().string());
      for (std::sregex_iterator it(text.begin(), text.end(), citation), end; it != end; ++it) {
        const std::string all = (*it)[1].str() + (*it)[2].str();
        for (std::sregex_iterator n(all.begin(), all.end(), number); n != end; ++n) cited.insert(n->str());
      }
    }
  EXPECT_GE(cited.size(), 7u) << "the code cites sections 1 to 7 and 4b";
  // headings "## 5. Pixel encoding" and "### 4b. Physically based ..."
  std::set<std::string> sections;
  std::istringstream in(test::read_file((kSource / "docs" / "DESIGN.md").string()));
  const std::regex heading(R"(^#{2,3} (\d[a-z]?)\. )");
  std::smatch m;
  for (std::string line; std::getline(in, line);)
    if (std::regex_search(line, m, heading)) sections.insert(m[1]);
  for (const std::string& s : cited)
    EXPECT_TRUE(sections.count(s)) << "the code cites DESIGN " << s << ", which docs/DESIGN.md lacks";
}

TEST(Docs, RenderHelpPointsToTheDocs) {
  const test::CliRun help = test::run("render --help");
  ASSERT_EQ(help.status, 0);
  for (const char* doc : {"docs/DESIGN.md", "docs/SHADING.md"}) {
    EXPECT_NE(help.output.find(doc), std::string::npos) << "pmr render --help names " << doc;
    EXPECT_TRUE(fs::exists(kSource / doc)) << doc;
  }
}

}  // namespace
}  // namespace pmr
