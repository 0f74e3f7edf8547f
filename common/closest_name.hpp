#pragma once
// "Did you mean" hints for misspelt keys and names in the input files.

#include <string>
#include <vector>

namespace talus {

// Names close to `word` among `candidates` for "did you mean" hints (edit distance <= 2, or a third
// of the word's length); empty when none is close.
std::string ClosestName(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace talus
