// docs/usage.md carries the help of every command verbatim (blocks written by
// scripts/update_usage.py); these tests fail when a help text and its block differ.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"

namespace qsmesh::cli {
namespace {

constexpr const char* kUpdate =
    "docs/usage.md is out of date with the help texts: build qsmesh and run "
    "scripts/update_usage.py, then commit docs/usage.md";

std::string read_doc() {
  std::ifstream in(QSMESH_USAGE_DOC, std::ios::binary);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The commands listed under "commands:" in the general help (as scripts/update_usage.py finds
/// them), so that a new command needs a block without this test being edited.
std::vector<std::string> commands() {
  std::vector<std::string> names;
  std::istringstream in(help(""));
  std::string line;
  bool inside = false;
  const std::regex entry(R"(^  ([a-z][a-z0-9-]*)\b.*)");
  while (std::getline(in, line)) {
    if (line == "commands:") {
      inside = true;
    } else if (inside && line.find_first_not_of(' ') == std::string::npos) {
      break;
    } else if (std::smatch m; inside && std::regex_match(line, m, entry)) {
      names.push_back(m[1]);
    }
  }
  return names;
}

/// Topic -> text of every help block of the document ("qsmesh" is the general help).
std::map<std::string, std::string> blocks(const std::string& doc) {
  std::map<std::string, std::string> out;
  const std::string open = "<!-- qsmesh-help ";
  for (std::size_t at = doc.find(open); at != std::string::npos; at = doc.find(open, at + 1)) {
    const std::size_t name_begin = at + open.size();
    const std::size_t name_end = doc.find_first_of(": ", name_begin);
    const std::size_t line_end = doc.find('\n', at);
    if (name_end == std::string::npos || line_end == std::string::npos) break;
    const std::string topic = doc.substr(name_begin, name_end - name_begin);
    const std::string fence = "```text\n";
    const std::string close = "```\n<!-- /qsmesh-help " + topic + " -->";
    const std::size_t body = line_end + 1;
    const std::size_t end = doc.find(close, body);
    if (doc.compare(body, fence.size(), fence) != 0 || end == std::string::npos) {
      out[topic] = "(malformed block: no ```text fence or no end marker)";
      continue;
    }
    out[topic] = doc.substr(body + fence.size(), end - body - fence.size());
  }
  return out;
}

/// The first line where a and b differ, for the failure message.
std::string first_difference(const std::string& doc, const std::string& help_text) {
  std::istringstream a(doc), b(help_text);
  std::string la, lb;
  for (int n = 1;; ++n) {
    const bool ga = static_cast<bool>(std::getline(a, la));
    const bool gb = static_cast<bool>(std::getline(b, lb));
    if (!ga && !gb) return "the line ends differ";
    if (!ga || !gb || la != lb)
      return "line " + std::to_string(n) + ": docs/usage.md has '" + (ga ? la : "(end)") +
             "', the help has '" + (gb ? lb : "(end)") + "'";
  }
}

TEST(UsageDoc, HelpListsCommands) {
  const std::vector<std::string> names = commands();
  EXPECT_GE(names.size(), 5u) << help("");
  for (const char* c : {"info", "mesh", "crossfield", "sizemap", "example"})
    EXPECT_NE(std::find(names.begin(), names.end(), c), names.end()) << c;
}

TEST(UsageDoc, EveryHelpTextIsInTheDocVerbatim) {
  const std::string doc = read_doc();
  ASSERT_FALSE(doc.empty()) << "cannot read " << QSMESH_USAGE_DOC;
  const std::map<std::string, std::string> found = blocks(doc);
  std::vector<std::string> topics{"qsmesh"};
  for (const std::string& c : commands()) topics.push_back(c);
  for (const std::string& topic : topics) {
    const std::string expected = help(topic == "qsmesh" ? "" : topic);
    const auto it = found.find(topic);
    const std::string command = topic == "qsmesh" ? "qsmesh --help" : "qsmesh " + topic + " --help";
    if (it == found.end()) {
      ADD_FAILURE() << "no block for `" << command << "`. " << kUpdate;
      continue;
    }
    EXPECT_EQ(it->second, expected) << "the block of `" << command << "` differs, "
                                    << first_difference(it->second, expected) << ". " << kUpdate;
  }
  for (const auto& [topic, text] : found)
    EXPECT_NE(std::find(topics.begin(), topics.end(), topic), topics.end())
        << "docs/usage.md has a block for '" << topic << "', which is no command. " << kUpdate;
}

TEST(UsageDoc, ParserSeesAChangedLine) {
  // The comparison is not vacuous: a doc whose mesh block lost a line is caught.
  const std::string doc = read_doc();
  const std::string text = help("mesh");
  const std::size_t second_line = text.find('\n') + 1;
  std::string edited = doc;
  const std::size_t at = edited.find(text);
  ASSERT_NE(at, std::string::npos) << "the mesh help is not in the doc. " << kUpdate;
  edited.erase(at + second_line, text.find('\n', second_line) + 1 - second_line);
  EXPECT_NE(blocks(edited).at("mesh"), text);
  EXPECT_EQ(blocks(doc).at("mesh"), text);
}

}  // namespace
}  // namespace qsmesh::cli
