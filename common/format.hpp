#pragma once
// Numbers and text as the outputs write them: the few formats of the outputs and messages, each
// written once.

#include <string>

namespace talus {

// `v` in the printf conversion `format` for one double, e.g. "%.3g" or "%.2f".
std::string FormatDouble(double v, const char* format);
// As FormatDouble, but `missing` for NaN (a value that does not exist: an empty CSV field, a
// report's "-").
std::string FormatOrMissing(double v, const char* format, const char* missing);
// Ten significant digits ("%.10g"): the numbers of messages and CSV files.
std::string TenDigits(double v);
// The shortest text that reads back as exactly `v` ("0.1", "1e-07", "nan", "-inf"): files that
// are read again.
std::string RoundTrip(double v);
// `text` with &, <, > and " escaped, for XML text and attribute values (SVG, HTML, QGIS styles).
std::string XmlEscaped(const std::string& text);

}  // namespace talus
