// JUnit XML for CI systems (Jenkins, GitLab, GitHub test reporters) from a gate report: one
// <testsuite> per sweep cell, one <testcase> per (cell, pipeline, check). A failed check is a
// <failure> whose message and text give the measured value, the limit and the reproduce command;
// a skipped check is <skipped>; a warning passes with its message in <system-out>.
// The format's schema as the tool writes it is ci/junit.xsd.
#pragma once

#include <string>
#include <string_view>

#include "validation/gate.hpp"

namespace sb::validation {

/// The XML document (UTF-8, with declaration). `name` names the <testsuites> root.
[[nodiscard]] std::string junit_xml(const GateReport& report, const std::string& name);

/// Escapes text for XML attribute values and character data: & < > " ' as entities, tab, newline
/// and carriage return as character references in attributes, and other control characters (not
/// allowed in XML 1.0) replaced by '?'.
[[nodiscard]] std::string xml_escape(std::string_view text, bool attribute);

}  // namespace sb::validation
