// JUnit XML from a gate report.
#include "validation/junit.hpp"

#include <cstdint>
#include <map>
#include <vector>

#include <fmt/format.h>

namespace sb::validation {

namespace {

/// The UTF-8 sequence at the start of `s` (its first byte >= 0x80): its length in bytes (1 for a
/// byte that starts none), and whether it is well formed (shortest form) and encodes a character
/// XML 1.0 allows.
struct Utf8Char {
  size_t length = 1;
  bool ok = false;
};
Utf8Char utf8_xml_char(std::string_view s) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b0 = byte(0);
  size_t n = 0;
  uint32_t cp = 0;
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    n = 2;
    cp = b0 & 0x1Fu;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    n = 3;
    cp = b0 & 0x0Fu;
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    n = 4;
    cp = b0 & 0x07u;
  } else {
    return {};  // a continuation byte, an overlong lead (C0, C1) or beyond U+10FFFF
  }
  if (s.size() < n) return {};
  for (size_t k = 1; k < n; ++k) {
    if ((byte(k) & 0xC0) != 0x80) return {};
    cp = (cp << 6) | (byte(k) & 0x3Fu);
  }
  const uint32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
  const bool allowed = cp >= least[n] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF) && cp != 0xFFFE &&
                       cp != 0xFFFF;
  return {n, allowed};
}

}  // namespace

std::string xml_escape(std::string_view text, bool attribute) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x80) {
      // A UTF-8 sequence is kept when it encodes an XML character; a broken or cut-off one, an
      // encoded surrogate, and U+FFFE / U+FFFF become '?' (the file declares UTF-8).
      const Utf8Char u = utf8_xml_char(text.substr(i));
      if (u.ok)
        out.append(text.substr(i, u.length));
      else
        out += '?';
      i += u.length - 1;
      continue;
    }
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += attribute ? "&quot;" : "\"";
        break;
      case '\'':
        out += attribute ? "&apos;" : "'";
        break;
      case '\t':
        out += attribute ? "&#9;" : "\t";
        break;
      case '\n':
        out += attribute ? "&#10;" : "\n";
        break;
      case '\r':
        out += "&#13;";
        break;
      default:
        out += c < 0x20 || c == 0x7f ? '?' : ch;
    }
  }
  return out;
}

namespace {

std::string attr(std::string_view s) {
  return xml_escape(s, true);
}
std::string text(std::string_view s) {
  return xml_escape(s, false);
}

/// One segment of a dotted class name: CI viewers split class names at '.' into a package tree
/// (and some at '/'), so a variant's "threshold_arcmin=2.5" would open a package "5".
std::string class_segment(std::string segment) {
  for (char& c : segment)
    if (c == '.' || c == '/' || c == '\\') c = '_';
  return segment;
}

/// A test case's name: pipeline and check, and for a check of one cell that cell's parameters
/// (its id after the scene name, which the class name holds; a generator's parameters, "scene:k=v|",
/// stay), so that the cells of a sweep over interaxials or resolutions are distinct test cases in
/// CI viewers, which know a test by class name and name.
std::string case_name(const GateCheck& c) {
  const std::string name = c.pipeline + " " + c.check;
  if (c.scene.empty()) return name;
  std::string cell = c.cell_id;
  if (cell.rfind(c.scene + "|", 0) == 0 || cell.rfind(c.scene + ":", 0) == 0) cell.erase(0, c.scene.size() + 1);
  return fmt::format("{} [{}]", name, cell);
}

}  // namespace

std::string junit_xml(const GateReport& report, const std::string& name) {
  // Cells in the order of the report; checks of a cell stay in report order.
  std::vector<std::string> order;
  std::map<std::string, std::vector<const GateCheck*>> by_cell;
  for (const GateCheck& c : report.checks) {
    if (!by_cell.count(c.cell_id)) order.push_back(c.cell_id);
    by_cell[c.cell_id].push_back(&c);
  }
  auto count = [](const std::vector<const GateCheck*>& checks, Verdict v) {
    int n = 0;
    for (const GateCheck* c : checks) n += c->verdict == v;
    return n;
  };
  std::vector<const GateCheck*> all;
  for (const GateCheck& c : report.checks) all.push_back(&c);

  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += fmt::format("<testsuites name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\">\n", attr(name),
                     all.size(), count(all, Verdict::fail), count(all, Verdict::skip));
  int index = 0;
  for (const std::string& cell_id : order) {
    const std::vector<const GateCheck*>& checks = by_cell[cell_id];
    out += fmt::format(
        "  <testsuite name=\"{}\" id=\"{}\" package=\"stereobench.gate\" tests=\"{}\" failures=\"{}\" errors=\"0\" "
        "skipped=\"{}\">\n",
        attr(cell_id), index++, checks.size(), count(checks, Verdict::fail), count(checks, Verdict::skip));
    // A check of the whole sweep (its completeness) belongs to no scene: no scene property, and
    // the class "gate.sweep" (an empty segment confuses tools that split class names at dots).
    if (!checks.front()->scene.empty())
      out += fmt::format("    <properties>\n      <property name=\"scene\" value=\"{}\"/>\n    </properties>\n",
                         attr(checks.front()->scene));
    for (const GateCheck* c : checks) {
      out += fmt::format("    <testcase name=\"{}\" classname=\"{}\"", attr(case_name(*c)),
                         attr(c->scene.empty() ? std::string("gate.sweep")
                                               : "gate." + class_segment(c->scene) + "." +
                                                     class_segment(c->pipeline)));
      if (c->verdict == Verdict::pass) {
        out += "/>\n";
        continue;
      }
      out += ">\n";
      if (c->verdict == Verdict::fail) {
        out += fmt::format("      <failure message=\"{}\" type=\"{}\">{}</failure>\n", attr(c->message), attr(c->check),
                           text(fmt::format("{}\ncell: {}\npipeline: {}\nreproduce: {}", c->message, c->cell_id,
                                            c->pipeline, c->reproduce)));
      } else if (c->verdict == Verdict::skip) {
        out += fmt::format("      <skipped message=\"{}\"/>\n", attr(c->message));
      } else {
        out += fmt::format("      <system-out>{}</system-out>\n",
                           text(fmt::format("WARNING: {}\nreproduce: {}", c->message, c->reproduce)));
      }
      out += "    </testcase>\n";
    }
    out += "  </testsuite>\n";
  }
  out += "</testsuites>\n";
  return out;
}

}  // namespace sb::validation
