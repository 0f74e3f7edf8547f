#include "io/barriers_csv.hpp"

#include <array>
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

// "%.10g", or an empty field for NaN (no rock counted).
std::string Field(double v) { return FormatOrMissing(v, "%.10g", ""); }

}  // namespace

const char* BarriersCsvWriter::Header() {
  return "barrier,type,rock,release,run,outcome,t_s,x_m,y_m,z_m,speed_m_s,"
         "translational_energy_J,rotational_energy_J,energy_J,passing_height_m,com_height_m,"
         "energy_after_J";
}

BarriersCsvWriter::BarriersCsvWriter(const std::string& path, const std::vector<Barrier>& barriers,
                                     const ensemble::ReleaseSpec& release)
    : file_(path, Header()), barriers_(barriers), release_(release) {}

void BarriersCsvWriter::Write(const ensemble::RockOutcome& rock) {
  const std::vector<BarrierEvent>& events = rock.result.barrier_events;
  if (events.empty()) return;
  const std::string run = CsvField(release_.ReleaseName(rock.release));
  for (const BarrierEvent& e : events) {
    const Barrier& b = barriers_[static_cast<std::size_t>(e.barrier)];
    std::fprintf(file_.get(),
                 "%s,%s,%ld,%d,%s,%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,"
                 "%.10g\n",
                 CsvField(b.name).c_str(), ToString(b.type), rock.rock, rock.release, run.c_str(),
                 ToString(e.outcome), e.t_s, e.position_m.x(), e.position_m.y(), e.position_m.z(),
                 e.speed_m_s, e.translational_energy_J, e.rotational_energy_J, e.energy_J(),
                 e.passing_height_m, e.com_height_m, e.energy_after_J);
  }
}

void BarriersCsvWriter::Commit() { file_.Commit(); }

std::vector<BarrierSummary> SummarizeBarriers(const std::string& csv_path,
                                              const std::vector<Barrier>& barriers, long rocks,
                                              std::size_t budget_bytes) {
  std::map<std::string, std::size_t> index;
  for (std::size_t b = 0; b < barriers.size(); ++b) index[barriers[b].name] = b;
  std::vector<BarrierSummary> out(barriers.size());
  // Column 3 b + q: impact energy and passing height (q = 0, 1) of each rock that reached barrier
  // b, energy after (q = 2) of each that passed. Each reading counts the outcomes afresh.
  const ColumnSource source = [&](const ColumnSink& emit) {
    for (BarrierSummary& s : out) s.reached = s.stopped = s.overtopped = s.broke_through = 0;
    CsvReader in(csv_path);
    const std::size_t barrier_column = in.Column("barrier"), outcome_column = in.Column("outcome");
    const std::array<std::size_t, 3> columns = {
        in.Column("energy_J"), in.Column("passing_height_m"), in.Column("energy_after_J")};
    std::vector<std::string> fields;
    while (in.Next(&fields)) {
      const std::string where = csv_path + ":" + std::to_string(in.line());
      const auto at = index.find(fields[barrier_column]);
      if (at == index.end())
        throw InputError(where + ": column 'barrier': '" + fields[barrier_column] +
                         "' is not a barrier of the scene");
      BarrierSummary& s = out[at->second];
      std::array<double, 3> v{};
      for (std::size_t q = 0; q < 3; ++q)
        v[q] = CsvFieldNumber(fields[columns[q]], where, in.header()[columns[q]]);
      const std::string& outcome = fields[outcome_column];
      ++s.reached;
      if (outcome == ToString(BarrierOutcome::kStopped)) {
        ++s.stopped;
      } else if (outcome == ToString(BarrierOutcome::kOvertopped)) {
        ++s.overtopped;
      } else if (outcome == ToString(BarrierOutcome::kBrokeThrough)) {
        ++s.broke_through;
      } else {
        throw InputError(where + ": column 'outcome': '" + outcome +
                         "': expected stopped, overtopped or broke_through");
      }
      emit(3 * at->second, v[0]);
      emit(3 * at->second + 1, v[1]);
      if (outcome != ToString(BarrierOutcome::kStopped)) emit(3 * at->second + 2, v[2]);
    }
  };
  const std::vector<ColumnStatistics> statistics =
      SummarizeColumns(source, 3 * barriers.size(), kCrossingPercents, budget_bytes);

  for (std::size_t b = 0; b < barriers.size(); ++b) {
    BarrierSummary& s = out[b];
    s.name = barriers[b].name;
    s.type = ToString(barriers[b].type);
    s.length_m = barriers[b].length_m();
    s.height_m = barriers[b].height_m;
    s.capacity_J = barriers[b].capacity_J;
    s.rocks = rocks;
    s.reach_probability = rocks > 0 ? double(s.reached) / double(rocks) : kNaN;
    s.passing_probability =
        rocks > 0 ? double(s.overtopped + s.broke_through) / double(rocks) : kNaN;
    s.impact_energy_J = CrossingStatisticsOf(statistics[3 * b]);
    s.passing_height_m = CrossingStatisticsOf(statistics[3 * b + 1]);
    s.passing_energy_J = CrossingStatisticsOf(statistics[3 * b + 2]);
  }
  return out;
}

std::string BarriersSummaryCsv(const std::vector<BarrierSummary>& summary) {
  std::string out =
      "name,type,length_m,height_m,capacity_J,rocks,reached,stopped,overtopped,broke_through,"
      "reach_probability,passing_probability";
  for (const char* quantity : {"impact_energy", "passing_height", "passing_energy"}) {
    const char* unit = std::string(quantity) == "passing_height" ? "m" : "J";
    for (const char* statistic : CrossingStatistics::kNames)
      out.append(",").append(quantity).append("_").append(statistic).append("_").append(unit);
  }
  out.append("\n");
  for (const BarrierSummary& s : summary) {
    out.append(CsvField(s.name)).append(",").append(s.type);
    for (double v : {s.length_m, s.height_m, s.capacity_J}) out.append(",").append(Field(v));
    for (long n : {s.rocks, s.reached, s.stopped, s.overtopped, s.broke_through})
      out.append(",").append(std::to_string(n));
    out.append(",").append(Field(s.reach_probability));
    out.append(",").append(Field(s.passing_probability));
    for (const CrossingStatistics* q :
         {&s.impact_energy_J, &s.passing_height_m, &s.passing_energy_J})
      for (double v : q->values) out.append(",").append(Field(v));
    out.append("\n");
  }
  return out;
}

}  // namespace talus::io
