#include "io/evaluation_lines_csv.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/format.hpp"
#include "io/rocks_csv.hpp"

namespace talus::io {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// "%.10g", or an empty field for NaN (no rock crossed).
std::string Field(double v) { return FormatOrMissing(v, "%.10g", ""); }

}  // namespace

const char* EvaluationLinesCsvWriter::Header() {
  return "line,rock,release,run,t_s,x_m,y_m,z_m,speed_m_s,translational_energy_J,"
         "rotational_energy_J,energy_J,com_height_m,bounce_height_m,crossings";
}

EvaluationLinesCsvWriter::EvaluationLinesCsvWriter(
    const std::string& path, const std::vector<ensemble::EvaluationLine>& lines,
    const ensemble::ReleaseSpec& release)
    : file_(path, Header()), lines_(lines), release_(release) {}

void EvaluationLinesCsvWriter::Write(const ensemble::RockOutcome& rock) {
  if (rock.line_crossings.empty()) return;
  const std::string run = CsvField(release_.ReleaseName(rock.release));
  for (const ensemble::LineCrossing& c : rock.line_crossings) {
    const std::string line = CsvField(lines_[static_cast<std::size_t>(c.line)].name);
    std::fprintf(file_.get(),
                 "%s,%ld,%d,%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%ld\n",
                 line.c_str(), rock.rock, rock.release, run.c_str(), c.t_s, c.position_m.x(),
                 c.position_m.y(), c.position_m.z(), c.speed_m_s, c.translational_energy_J,
                 c.rotational_energy_J, c.energy_J(), c.com_height_m, c.bounce_height_m,
                 c.crossings);
  }
}

void EvaluationLinesCsvWriter::Commit() { file_.Commit(); }

CrossingStatistics CrossingStatisticsOf(const ColumnStatistics& column) {
  CrossingStatistics s;
  s.values[0] = column.mean();
  for (std::size_t k = 0; k < kCrossingPercents.size(); ++k)
    s.values[k + 1] = column.percentiles[k];
  return s;
}

CrossingStatistics StatisticsOf(const std::vector<double>& values) {
  const ColumnSource source = [&values](const ColumnSink& emit) {
    for (double v : values) emit(0, v);
  };
  return CrossingStatisticsOf(SummarizeColumns(source, 1, kCrossingPercents)[0]);
}

std::vector<EvaluationLineSummary> SummarizeEvaluationLines(
    const std::string& csv_path, const std::vector<ensemble::EvaluationLine>& lines, long rocks,
    std::size_t budget_bytes) {
  std::map<std::string, std::size_t> index;
  for (std::size_t l = 0; l < lines.size(); ++l) index[lines[l].name] = l;
  // Column 4 l + q: speed, energy, centre-of-mass height and bounce height (q) of each rock that
  // crossed line l.
  const ColumnSource source = [&](const ColumnSink& emit) {
    CsvReader in(csv_path);
    const std::size_t line_column = in.Column("line");
    const std::array<std::size_t, 4> columns = {in.Column("speed_m_s"), in.Column("energy_J"),
                                                in.Column("com_height_m"),
                                                in.Column("bounce_height_m")};
    std::vector<std::string> fields;
    while (in.Next(&fields)) {
      const auto at = index.find(fields[line_column]);
      if (at == index.end())
        throw InputError(csv_path + ":" + std::to_string(in.line()) + ": column 'line': '" +
                         fields[line_column] + "' is not an evaluation line of the scene");
      for (std::size_t q = 0; q < 4; ++q)
        emit(4 * at->second + q,
             CsvFieldNumber(fields[columns[q]], csv_path + ":" + std::to_string(in.line()),
                            in.header()[columns[q]]));
    }
  };
  const std::vector<ColumnStatistics> statistics =
      SummarizeColumns(source, 4 * lines.size(), kCrossingPercents, budget_bytes);

  std::vector<EvaluationLineSummary> out;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    EvaluationLineSummary& s = out.emplace_back();
    s.name = lines[l].name;
    s.length_m = lines[l].length_m();
    s.rocks = rocks;
    s.crossed = statistics[4 * l].count;
    s.passing_probability = rocks > 0 ? double(s.crossed) / double(rocks) : kNaN;
    s.speed_m_s = CrossingStatisticsOf(statistics[4 * l]);
    s.energy_J = CrossingStatisticsOf(statistics[4 * l + 1]);
    s.com_height_m = CrossingStatisticsOf(statistics[4 * l + 2]);
    s.bounce_height_m = CrossingStatisticsOf(statistics[4 * l + 3]);
  }
  return out;
}

std::string EvaluationLinesSummaryCsv(const std::vector<EvaluationLineSummary>& summary) {
  std::string out = "name,length_m,rocks,crossed,passing_probability";
  for (const auto& [quantity, unit] :
       {std::pair{"speed", "m_s"}, std::pair{"energy", "J"}, std::pair{"com_height", "m"},
        std::pair{"bounce_height", "m"}})
    for (const char* statistic : CrossingStatistics::kNames)
      out.append(",").append(quantity).append("_").append(statistic).append("_").append(unit);
  out.append("\n");
  for (const EvaluationLineSummary& s : summary) {
    out.append(CsvField(s.name)).append(",").append(Field(s.length_m));
    out.append(",").append(std::to_string(s.rocks)).append(",").append(std::to_string(s.crossed));
    out.append(",").append(Field(s.passing_probability));
    for (const CrossingStatistics* q :
         {&s.speed_m_s, &s.energy_J, &s.com_height_m, &s.bounce_height_m})
      for (double v : q->values) out.append(",").append(Field(v));
    out.append("\n");
  }
  return out;
}

}  // namespace talus::io
