#pragma once
// report.html of `talus validate`: one self-contained page (html_page.hpp) with the warnings, the
// scores per observation kind with their units and skills, the observed-vs-simulated and PIT
// plots (inline SVG, the panels of observed_vs_simulated.svg and pit.svg), the deposits map when
// the event has deposits, one row per run and observation, and how the rocks ended. Like
// report.html of a simulation it shows no timings or thread counts: the same event gives the same
// page on any machine.

#include <string>

#include "fieldobs/validation.hpp"

namespace talus::io {

struct ValidationReportInput {
  std::string scores_json;  // scores.json's text
  const fieldobs::ValidationReport* report = nullptr;
  std::string deposits_png;  // deposits.png's bytes, or empty
};

std::string ValidationReportHtml(const ValidationReportInput& input);

}  // namespace talus::io
