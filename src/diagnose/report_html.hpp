// The diagnosis report's HTML page: headline, findings and limits tables, inline figures, raw text folded away.
#pragma once

#include <string>
#include <vector>

#include "rollsim/diagnose/diagnose.hpp"

namespace rollsim::diag {

/// One drawn figure: gnuplot's SVG (with its XML prolog) and the caption it is shown with.
struct HtmlFigure {
  std::string id, caption, svg;
};

/// The page's figures by section; an empty section is said in words, not drawn.
struct ReportFigures {
  std::vector<HtmlFigure> regimes, residuals, road_profiles;
};

/// Text with the five HTML-special characters (& < > " ') as entities: safe in element content and attributes.
std::string html_escape(const std::string& text);

/// The self-contained page (no external resource: styles inline, SVGs inline with ids prefixed per figure).
std::string report_page(const Diagnosis& d, const std::string& title, const ReportFigures& figures);

}  // namespace rollsim::diag
