#include "io/tree_impacts_csv.hpp"

#include <set>

#include "common/csv_table.hpp"
#include "io/rocks_csv.hpp"

namespace talus::io {

const char* TreeImpactsCsvWriter::Header() {
  return "tree,rock,release,run,tree_x_m,tree_y_m,dbh_cm,impacts,t_s,x_m,y_m,z_m,energy_J,"
         "absorbed_J,broken,species";
}

TreeImpactsCsvWriter::TreeImpactsCsvWriter(const std::string& path, const Forest& forest,
                                           const ensemble::ReleaseSpec& release)
    : file_(path, Header()), forest_(forest), release_(release) {}

void TreeImpactsCsvWriter::Write(const ensemble::RockOutcome& rock) {
  const std::vector<StemHit>& hits = rock.result.stem_hits;
  if (hits.empty()) return;
  const std::string run = CsvField(release_.ReleaseName(rock.release));
  for (const StemHit& h : hits) {
    const Stem& stem = forest_.stems()[static_cast<std::size_t>(h.stem)];
    const std::string species =
        stem.species >= 0
            ? CsvField(forest_.model().species[static_cast<std::size_t>(stem.species)].name)
            : "";
    std::fprintf(file_.get(),
                 "%d,%ld,%d,%s,%.10g,%.10g,%.10g,%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d,%s\n",
                 h.stem, rock.rock, rock.release, run.c_str(), stem.position_m.x(),
                 stem.position_m.y(), 100 * stem.dbh_m, h.impacts, h.t_s, h.position_m.x(),
                 h.position_m.y(), h.position_m.z(), h.energy_J, h.absorbed_J, h.broken ? 1 : 0,
                 species.c_str());
  }
}

void TreeImpactsCsvWriter::Commit() { file_.Commit(); }

TreeImpactSummary SummarizeTreeImpacts(const std::string& csv_path) {
  const CsvTable table = CsvTable::Read(csv_path);
  table.Require({"tree", "rock", "impacts", "absorbed_J", "broken"});
  TreeImpactSummary s;
  std::set<long> stems, hitting, breaking;
  for (int row = 0; row < table.rows(); ++row) {
    const long tree = static_cast<long>(table.NonNegativeNumber(row, "tree"));
    const long rock = static_cast<long>(table.NonNegativeNumber(row, "rock"));
    const bool broken = table.NonNegativeNumber(row, "broken") > 0;
    ++s.rows;
    s.impacts += static_cast<long>(table.NonNegativeNumber(row, "impacts"));
    s.absorbed_J += table.NonNegativeNumber(row, "absorbed_J");
    stems.insert(tree);
    hitting.insert(rock);
    if (broken) {
      ++s.breakages;
      breaking.insert(rock);
    }
  }
  s.stems_hit = static_cast<long>(stems.size());
  s.rocks_hitting = static_cast<long>(hitting.size());
  s.rocks_breaking = static_cast<long>(breaking.size());
  return s;
}

}  // namespace talus::io
