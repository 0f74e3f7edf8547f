#include "io/trajectory_file.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

namespace talus::io {
namespace {

// One HDF5 identifier, closed with its own close function when it goes out of scope (errors
// ignored there: that is the abandon path). Close() reports the error instead.
class Handle {
 public:
  using CloseFunction = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, CloseFunction close) : id_(id), close_(close) {}
  Handle(Handle&& other) noexcept { *this = std::move(other); }
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      Close();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      close_ = other.close_;
    }
    return *this;
  }
  ~Handle() { Close(); }
  hid_t get() const { return id_; }
  // Closes now; false when HDF5 reports an error (e.g. the data it flushes cannot be written).
  bool Close() {
    const hid_t id = std::exchange(id_, H5I_INVALID_HID);
    return id < 0 || close_(id) >= 0;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  CloseFunction close_ = nullptr;
};

herr_t WalkError(unsigned depth, const H5E_error2_t* error, void* data) {
  auto* reason = static_cast<std::string*>(data);
  const std::string desc = error->desc ? error->desc : "";
  // The system's words for a failed read or write ("No space left on device"), else the message
  // of the innermost function.
  const std::string marker = "error message = '";
  if (const std::size_t at = desc.find(marker); at != std::string::npos) {
    const std::size_t from = at + marker.size();
    *reason = desc.substr(from, desc.find('\'', from) - from);
    return 1;  // stop walking
  }
  if (depth == 0) *reason = desc;
  return 0;
}

// An HDF5 failure and its reason, read from HDF5's error stack where it happened (the next HDF5
// call, even a successful close while unwinding, clears the stack).
struct Hdf5Failure {
  std::string reason;
};

[[noreturn]] void Fail(const char* what) {
  std::string reason;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, WalkError, &reason);
  throw Hdf5Failure{reason.empty() ? std::string("HDF5 failed to ") + what : reason};
}

// HDF5 would print its error stack on stderr; every failure becomes one exception instead. (The
// setting is per thread in thread-safe builds, so each entry point makes it.)
void SilenceHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

// HDF5's exit handler (H5_term_library) closes the files still open at exit. A file whose close
// failed is one HDF5 can neither close nor drop, and that handler then crashes on it (SIGSEGV in
// H5F__close_cb). Abandon below avoids such failures where it can; where it cannot (a hard
// file-size limit hit while HDF5 flushes), the process must still end normally. Every file is
// closed explicitly here, so the handler has nothing else to do at exit but free memory: it is
// turned off. This runs at static initialisation, before the first HDF5 call of a program that
// links this file (afterwards the handler is registered already; HDF5's C++ library, which
// talus does not use, registers one of its own when it is loaded).
[[maybe_unused]] const bool kNoHdf5ExitHandler = H5dont_atexit() >= 0;

hid_t Check(hid_t id, const char* what) {
  if (id < 0) Fail(what);
  return id;
}

void Check(herr_t status, const char* what) {
  if (status < 0) Fail(what);
}

// Creation properties that leave out the object's access/modification/change timestamps, so
// that the same trajectories give the same bytes (the determinism contract covers every file).
Handle UntimedCreation(hid_t property_class) {
  Handle properties(Check(H5Pcreate(property_class), "create properties"), H5Pclose);
  Check(H5Pset_obj_track_times(properties.get(), false), "set properties");
  return properties;
}

Handle CreateGroup(hid_t parent, const char* name) {
  const Handle properties = UntimedCreation(H5P_GROUP_CREATE);
  return Handle(
      Check(H5Gcreate2(parent, name, H5P_DEFAULT, properties.get(), H5P_DEFAULT), "create a group"),
      H5Gclose);
}

void Attribute(hid_t object, const char* name, const std::vector<double>& values) {
  const hsize_t n = values.size();
  const Handle space(Check(H5Screate_simple(1, &n, nullptr), "create a dataspace"), H5Sclose);
  Handle attribute(
      Check(H5Acreate2(object, name, H5T_NATIVE_DOUBLE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
            "create an attribute"),
      H5Aclose);
  Check(H5Awrite(attribute.get(), H5T_NATIVE_DOUBLE, values.data()), "write an attribute");
  if (!attribute.Close()) Fail("write an attribute");
}

// A variable-length UTF-8 string attribute (h5py reads it as str).
void StringAttribute(hid_t object, const char* name, const std::string& value) {
  const Handle type(Check(H5Tcopy(H5T_C_S1), "create a string type"), H5Tclose);
  Check(H5Tset_size(type.get(), H5T_VARIABLE), "create a string type");
  Check(H5Tset_cset(type.get(), H5T_CSET_UTF8), "create a string type");
  const Handle space(Check(H5Screate(H5S_SCALAR), "create a dataspace"), H5Sclose);
  Handle attribute(
      Check(H5Acreate2(object, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
            "create an attribute"),
      H5Aclose);
  const char* text = value.c_str();
  Check(H5Awrite(attribute.get(), type.get(), &text), "write an attribute");
  if (!attribute.Close()) Fail("write an attribute");
}

void IntegerAttribute(hid_t object, const char* name, long value) {
  const Handle space(Check(H5Screate(H5S_SCALAR), "create a dataspace"), H5Sclose);
  Handle attribute(
      Check(H5Acreate2(object, name, H5T_NATIVE_INT64, space.get(), H5P_DEFAULT, H5P_DEFAULT),
            "create an attribute"),
      H5Aclose);
  const std::int64_t v = value;
  Check(H5Awrite(attribute.get(), H5T_NATIVE_INT64, &v), "write an attribute");
  if (!attribute.Close()) Fail("write an attribute");
}

// Rows per chunk of every table: 8192 samples are 192 kB of positions before compression.
constexpr hsize_t kChunkRows = 8192;

// Whether a table is deflate-compressed. Deflate takes the shuffled bytes of doubles whose
// mantissas vary in every sample (velocities, quaternions, scars) to 86 % of their size at a
// quarter of a second per 10^7 of them; times, contact flags and the rocks' index to 6 %, positions
// and angular velocities (zero at rest) to 70 and 43 % (cases/tirol, 200 rocks; bench/README.md,
// "What a run pays besides its rocks").
enum class Deflate : bool { kNo, kYes };

// One growing table of `width` values of `type` per row: chunked (kChunkRows rows), with
// attributes units and frame, and with kYes shuffled and deflate-compressed. Rows are buffered and
// written a whole chunk at a time (the rest by Finish), so that each chunk is compressed once and
// the bytes depend on the rows alone, not on how they arrived.
class Column {
 public:
  Column(hid_t parent, const char* name, hid_t type, hsize_t width, const char* units,
         const char* frame, Deflate deflate = Deflate::kYes)
      : type_(type), width_(width), row_bytes_(H5Tget_size(type) * width) {
    const hsize_t dims[2] = {0, width}, max[2] = {H5S_UNLIMITED, width};
    const hsize_t chunk[2] = {kChunkRows, width};
    const int rank = width == 1 ? 1 : 2;
    const Handle space(Check(H5Screate_simple(rank, dims, max), "create a dataspace"), H5Sclose);
    const Handle properties = UntimedCreation(H5P_DATASET_CREATE);
    Check(H5Pset_chunk(properties.get(), rank, chunk), "set chunks");
    if (deflate == Deflate::kYes) {
      Check(H5Pset_shuffle(properties.get()), "set shuffle");
      Check(H5Pset_deflate(properties.get(), 4), "set deflate");
    }
    set_ = Handle(Check(H5Dcreate2(parent, name, type, space.get(), H5P_DEFAULT, properties.get(),
                                   H5P_DEFAULT),
                        "create a dataset"),
                  H5Dclose);
    StringAttribute(set_.get(), "units", units);
    StringAttribute(set_.get(), "frame", frame);
  }

  // Appends one row: `width` values of the column's type.
  void Append(const void* row) {
    const auto* bytes = static_cast<const unsigned char*>(row);
    buffer_.insert(buffer_.end(), bytes, bytes + row_bytes_);
    if (buffer_.size() >= kChunkRows * row_bytes_) Write(kChunkRows);
  }
  // Writes the rows still buffered and closes the dataset (closing writes what HDF5 holds).
  void Finish() {
    Write(buffer_.size() / row_bytes_);
    if (!set_.Close()) Fail("write data");
  }
  hsize_t rows() const { return rows_written_ + buffer_.size() / row_bytes_; }

 private:
  void Write(hsize_t n) {
    if (n == 0) return;
    const hsize_t extent[2] = {rows_written_ + n, width_};
    Check(H5Dset_extent(set_.get(), extent), "extend a dataset");
    const Handle file_space(Check(H5Dget_space(set_.get()), "select rows"), H5Sclose);
    const hsize_t start[2] = {rows_written_, 0}, count[2] = {n, width_};
    Check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr),
          "select rows");
    const int rank = width_ == 1 ? 1 : 2;
    const Handle memory(Check(H5Screate_simple(rank, count, nullptr), "create a dataspace"),
                        H5Sclose);
    Check(H5Dwrite(set_.get(), type_, memory.get(), file_space.get(), H5P_DEFAULT, buffer_.data()),
          "write data");
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(n * row_bytes_));
    rows_written_ += n;
  }

  Handle set_;
  hid_t type_;
  hsize_t width_, row_bytes_, rows_written_ = 0;
  std::vector<unsigned char> buffer_;
};

// Closes a file that is being abandoned (its temporary file is about to be removed) without
// writing what HDF5 still holds for it to disk: its descriptor is first pointed at an anonymous
// memory file, and a soft file-size limit is lifted meanwhile. HDF5 cannot drop a file whose close
// fails: it keeps a half-freed file that crashes it at exit (SIGSEGV in H5F__close_cb). Under a
// hard file-size limit (`ulimit -f` sets both) writes to the memory file past the limit would fail
// too, so the descriptor is pointed at /dev/null instead, where every write succeeds.
// `close_objects` closes the file's open objects (their cached data goes to the same place).
template <class CloseObjects>
void Abandon(Handle& file, CloseObjects close_objects) {
  void* vfd = nullptr;
  if (file.get() < 0 || H5Fget_vfd_handle(file.get(), H5P_DEFAULT, &vfd) < 0 || !vfd) {
    close_objects();
    file.Close();
    return;
  }
  const int fd = *static_cast<int*>(vfd);  // the default (sec2) driver's descriptor
  rlimit limit{};
  const bool got = ::getrlimit(RLIMIT_FSIZE, &limit) == 0;
  const bool hard = got && limit.rlim_max != RLIM_INFINITY;
  const int target = hard ? ::open("/dev/null", O_RDWR | O_CLOEXEC)
                          : ::memfd_create("talus-abandoned.h5", MFD_CLOEXEC);
  if (target >= 0) {
    ::dup2(target, fd);
    ::close(target);
  }
  const bool lift = got && limit.rlim_cur != limit.rlim_max;
  if (lift) {
    const rlimit lifted{limit.rlim_max, limit.rlim_max};
    ::setrlimit(RLIMIT_FSIZE, &lifted);
  }
  close_objects();
  file.Close();
  if (lift) ::setrlimit(RLIMIT_FSIZE, &limit);
}

}  // namespace

struct TrajectoryWriter::Impl {
  Handle file;  // declared first: closed last
  Handle samples_group, rocks_group;
  // /samples: one row per sample of every rock, rock after rock.
  std::optional<Column> t, position, quaternion, velocity, angular, contact, scar;
  // /rocks: one row per rock, the index into /samples and the rock's shape.
  std::optional<Column> rock, first_sample, sample_count, mass, inertia;
  double mass_kg = 0;
  std::vector<double> inertia_kg_m2;
  long last_rock = -1;
  bool committed = false;

  std::vector<Column*> columns() {
    return {&*t,    &*position, &*quaternion,   &*velocity,     &*angular, &*contact,
            &*scar, &*rock,     &*first_sample, &*sample_count, &*mass,    &*inertia};
  }
  ~Impl() {
    if (committed) return;
    Abandon(file, [this] {
      for (auto* c : {&t, &position, &quaternion, &velocity, &angular, &contact, &scar, &rock,
                      &first_sample, &sample_count, &mass, &inertia})
        c->reset();
      samples_group.Close();
      rocks_group.Close();
    });
  }
};

TrajectoryWriter::TrajectoryWriter(const std::string& path, const RockShape& rock,
                                   const std::string& crs_wkt)
    : file_(path) {
  SilenceHdf5();
  impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  m.mass_kg = rock.mass_kg;
  m.inertia_kg_m2 = {rock.inertia_kg_m2.x(), rock.inertia_kg_m2.y(), rock.inertia_kg_m2.z()};
  try {
    m.file =
        Handle(Check(H5Fcreate(file_.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                     "create the file"),
               H5Fclose);
    const hid_t root = m.file.get();
    StringAttribute(root, "format", kTrajectoryFormat);
    IntegerAttribute(root, "format_version", kTrajectoryFormatVersion);
    StringAttribute(root, "crs", crs_wkt.empty() ? std::string(kLocalCrs) : crs_wkt);
    Attribute(root, "mass_kg", {m.mass_kg});
    Attribute(root, "principal_inertia_kg_m2", m.inertia_kg_m2);
    m.samples_group = CreateGroup(root, "/samples");
    m.rocks_group = CreateGroup(root, "/rocks");
    const hid_t d = H5T_NATIVE_DOUBLE, g = m.samples_group.get(), r = m.rocks_group.get();
    m.t.emplace(g, "t", d, 1, "s", "none");
    m.position.emplace(g, "position", d, 3, "m", "world");
    m.quaternion.emplace(g, "quaternion", d, 4, "1", "world", Deflate::kNo);
    m.velocity.emplace(g, "velocity", d, 3, "m/s", "world", Deflate::kNo);
    m.angular.emplace(g, "angular_velocity", d, 3, "rad/s", "world");
    m.contact.emplace(g, "contact", H5T_NATIVE_UINT8, 1, "1", "none");
    m.scar.emplace(g, "scar", d, 1, "m", "none", Deflate::kNo);
    m.rock.emplace(r, "rock", H5T_NATIVE_INT64, 1, "1", "none");
    m.first_sample.emplace(r, "first_sample", H5T_NATIVE_INT64, 1, "1", "none");
    m.sample_count.emplace(r, "sample_count", H5T_NATIVE_INT64, 1, "1", "none");
    m.mass.emplace(r, "mass_kg", d, 1, "kg", "none");
    m.inertia.emplace(r, "principal_inertia_kg_m2", d, 3, "kg m2", "body");
  } catch (const Hdf5Failure& failure) {
    const std::string reason = failure.reason;
    impl_.reset();
    throw std::runtime_error("cannot create " + file_.final_path() + ": " + reason);
  }
}

TrajectoryWriter::~TrajectoryWriter() = default;

void TrajectoryWriter::Write(const ensemble::RockOutcome& rock) {
  StoredTrajectory stored;
  // Each rock's own shape (runs with blocks, or a shape per rock), else the scene's rock.
  if (rock.shape) {
    stored.mass_kg = rock.shape->mass_kg;
    stored.principal_inertia_kg_m2 = rock.shape->inertia_kg_m2;
  } else if (impl_) {
    stored.mass_kg = impl_->mass_kg;
    stored.principal_inertia_kg_m2 = Eigen::Vector3d(impl_->inertia_kg_m2.data());
  }
  stored.samples = rock.trajectory;
  Write(rock.rock, stored);
}

void TrajectoryWriter::Write(long rock, const StoredTrajectory& stored) {
  if (!impl_) throw std::logic_error("TrajectoryWriter::Write after a failure or Commit");
  if (rock <= impl_->last_rock)
    throw std::logic_error("TrajectoryWriter::Write: rocks must come in increasing order");
  SilenceHdf5();
  Impl& m = *impl_;
  try {
    const std::int64_t index[3] = {rock, static_cast<std::int64_t>(m.t->rows()),
                                   static_cast<std::int64_t>(stored.samples.size())};
    m.rock->Append(&index[0]);
    m.first_sample->Append(&index[1]);
    m.sample_count->Append(&index[2]);
    m.mass->Append(&stored.mass_kg);
    m.inertia->Append(stored.principal_inertia_kg_m2.data());
    for (const ensemble::TrajectorySample& s : stored.samples) {
      const double q[4] = {s.orientation.w(), s.orientation.x(), s.orientation.y(),
                           s.orientation.z()};
      const std::uint8_t contact = s.contact ? 1 : 0;
      m.t->Append(&s.t_s);
      m.position->Append(s.position_m.data());
      m.quaternion->Append(q);
      m.velocity->Append(s.velocity_m_s.data());
      m.angular->Append(s.angular_velocity_rad_s.data());
      m.contact->Append(&contact);
      m.scar->Append(&s.scar_m);
    }
    m.last_rock = rock;
  } catch (const Hdf5Failure& failure) {
    const std::string reason = failure.reason;
    impl_.reset();  // abandon the file: nothing more is written to it
    throw std::runtime_error("cannot write rock " + std::to_string(rock) + " to " +
                             file_.final_path() + ": " + reason);
  }
}

void TrajectoryWriter::Commit() {
  if (!impl_) throw std::logic_error("TrajectoryWriter::Commit after a failure or Commit");
  SilenceHdf5();
  // Flush first: a write that fails while closing must not pass for a complete file.
  try {
    for (Column* c : impl_->columns()) c->Finish();
    Check(H5Fflush(impl_->file.get(), H5F_SCOPE_GLOBAL), "flush the file");
    if (!impl_->samples_group.Close() || !impl_->rocks_group.Close()) Fail("close a group");
    if (!impl_->file.Close()) Fail("close the file");
    impl_->committed = true;
  } catch (const Hdf5Failure& failure) {
    impl_.reset();
    throw std::runtime_error("cannot write " + file_.final_path() + ": " + failure.reason);
  }
  impl_.reset();
  file_.Commit();
}

namespace {

// Reads rows [first, first + n) of a table of `width` values per row.
template <class T>
std::vector<T> ReadRows(hid_t set, hid_t type, hsize_t first, hsize_t n, hsize_t width) {
  std::vector<T> values(static_cast<std::size_t>(n * width));
  if (n == 0) return values;
  const Handle file_space(Check(H5Dget_space(set), "select rows"), H5Sclose);
  const hsize_t start[2] = {first, 0}, count[2] = {n, width};
  Check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr),
        "select rows");
  const Handle memory(Check(H5Screate_simple(width == 1 ? 1 : 2, count, nullptr), "dataspace"),
                      H5Sclose);
  Check(H5Dread(set, type, memory.get(), file_space.get(), H5P_DEFAULT, values.data()),
        "read data");
  return values;
}

// Rows in a table, checking that it has `width` values per row.
hsize_t Rows(hid_t set, hsize_t width, const char* name) {
  const Handle space(Check(H5Dget_space(set), name), H5Sclose);
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1 || rank > 2 || H5Sget_simple_extent_dims(space.get(), dims, nullptr) < 0 ||
      (rank == 2 ? dims[1] : 1) != width)
    throw Hdf5Failure{std::string(name) + " has an unexpected shape"};
  return dims[0];
}

std::string ReadStringAttribute(hid_t object, const char* name) {
  const Handle attribute(Check(H5Aopen(object, name, H5P_DEFAULT), name), H5Aclose);
  const Handle type(Check(H5Aget_type(attribute.get()), name), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) <= 0)
    throw Hdf5Failure{std::string(name) + " is not a string"};
  char* text = nullptr;
  Check(H5Aread(attribute.get(), type.get(), &text), name);
  std::string out = text ? text : "";
  const Handle space(Check(H5Aget_space(attribute.get()), name), H5Sclose);
  H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, &text);
  return out;
}

}  // namespace

struct TrajectoryReader::Impl {
  Handle file;
  // The sample tables in the order of kSampleTables, and the index tables.
  std::vector<Handle> samples;
  Handle rock, first_sample, sample_count, mass, inertia;
  hsize_t rocks = 0, sample_rows = 0;
  // One block of index rows, [block_first, block_first + block_rock.size()).
  hsize_t block_first = 0;
  std::vector<std::int64_t> block_rock, block_first_sample, block_count;

  Handle Open(const char* name) const {
    return Handle(Check(H5Dopen2(file.get(), name, H5P_DEFAULT), name), H5Dclose);
  }
  // Loads the index block holding `row`.
  void Load(hsize_t row) {
    block_first = row - row % kChunkRows;
    const hsize_t n = std::min(kChunkRows, rocks - block_first);
    block_rock = ReadRows<std::int64_t>(rock.get(), H5T_NATIVE_INT64, block_first, n, 1);
    block_first_sample =
        ReadRows<std::int64_t>(first_sample.get(), H5T_NATIVE_INT64, block_first, n, 1);
    block_count = ReadRows<std::int64_t>(sample_count.get(), H5T_NATIVE_INT64, block_first, n, 1);
  }
  std::int64_t RockAt(hsize_t row) {
    if (row < block_first || row >= block_first + block_rock.size()) Load(row);
    return block_rock[row - block_first];
  }
};

TrajectoryReader::TrajectoryReader(const std::string& path) : path_(path) {
  SilenceHdf5();
  impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  try {
    m.file = Handle(Check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open the file"),
                    H5Fclose);
    if (H5Aexists(m.file.get(), "format_version") <= 0)
      throw Hdf5Failure{"not a trajectories.h5 of this version of talus (no format_version)"};
    std::int64_t version = 0;
    {
      const Handle a(Check(H5Aopen(m.file.get(), "format_version", H5P_DEFAULT), "format"),
                     H5Aclose);
      Check(H5Aread(a.get(), H5T_NATIVE_INT64, &version), "format_version");
    }
    if (ReadStringAttribute(m.file.get(), "format") != kTrajectoryFormat ||
        version != kTrajectoryFormatVersion)
      throw Hdf5Failure{"format version " + std::to_string(version) + ", this talus reads " +
                        std::to_string(kTrajectoryFormatVersion)};
    const std::pair<const char*, hsize_t> tables[] = {
        {"/samples/t", 1},        {"/samples/position", 3},         {"/samples/quaternion", 4},
        {"/samples/velocity", 3}, {"/samples/angular_velocity", 3}, {"/samples/contact", 1},
        {"/samples/scar", 1}};
    for (const auto& [name, width] : tables) {
      m.samples.push_back(m.Open(name));
      const hsize_t rows = Rows(m.samples.back().get(), width, name);
      if (name == tables[0].first) m.sample_rows = rows;
      if (rows != m.sample_rows) throw Hdf5Failure{"sample tables of different lengths"};
    }
    m.rock = m.Open("/rocks/rock");
    m.first_sample = m.Open("/rocks/first_sample");
    m.sample_count = m.Open("/rocks/sample_count");
    m.mass = m.Open("/rocks/mass_kg");
    m.inertia = m.Open("/rocks/principal_inertia_kg_m2");
    m.rocks = Rows(m.rock.get(), 1, "/rocks/rock");
    if (Rows(m.first_sample.get(), 1, "first_sample") != m.rocks ||
        Rows(m.sample_count.get(), 1, "sample_count") != m.rocks ||
        Rows(m.mass.get(), 1, "mass_kg") != m.rocks ||
        Rows(m.inertia.get(), 3, "principal_inertia_kg_m2") != m.rocks)
      throw Hdf5Failure{"rock tables of different lengths"};
  } catch (const Hdf5Failure& failure) {
    throw std::runtime_error("cannot read " + path + ": " + failure.reason);
  }
}

TrajectoryReader::~TrajectoryReader() = default;

StoredTrajectory TrajectoryReader::Read(long rock) const {
  SilenceHdf5();
  Impl& m = *impl_;
  try {
    if (m.rocks == 0) throw Hdf5Failure{"no such rock"};
    // Rocks are stored in increasing order, usually consecutive: try rock - first rock, else
    // bisect.
    const std::int64_t first = m.RockAt(0);
    hsize_t row = 0;
    if (rock >= first && hsize_t(rock - first) < m.rocks &&
        m.RockAt(hsize_t(rock - first)) == rock) {
      row = hsize_t(rock - first);
    } else {
      hsize_t lo = 0, hi = m.rocks;  // the row is in [lo, hi)
      while (hi - lo > 1) {
        const hsize_t mid = lo + (hi - lo) / 2;
        (m.RockAt(mid) <= rock ? lo : hi) = mid;
      }
      if (m.RockAt(lo) != rock) throw Hdf5Failure{"no such rock"};
      row = lo;
    }
    m.RockAt(row);  // its block
    const hsize_t from = static_cast<hsize_t>(m.block_first_sample[row - m.block_first]);
    const hsize_t n = static_cast<hsize_t>(m.block_count[row - m.block_first]);
    if (from + n > m.sample_rows || from + n < from) throw Hdf5Failure{"index beyond the samples"};
    StoredTrajectory out;
    const hid_t d = H5T_NATIVE_DOUBLE;
    out.mass_kg = ReadRows<double>(m.mass.get(), d, row, 1, 1)[0];
    out.principal_inertia_kg_m2 =
        Eigen::Vector3d(ReadRows<double>(m.inertia.get(), d, row, 1, 3).data());
    const auto t = ReadRows<double>(m.samples[0].get(), d, from, n, 1);
    const auto position = ReadRows<double>(m.samples[1].get(), d, from, n, 3);
    const auto quaternion = ReadRows<double>(m.samples[2].get(), d, from, n, 4);
    const auto velocity = ReadRows<double>(m.samples[3].get(), d, from, n, 3);
    const auto angular = ReadRows<double>(m.samples[4].get(), d, from, n, 3);
    const auto contact = ReadRows<std::uint8_t>(m.samples[5].get(), H5T_NATIVE_UINT8, from, n, 1);
    const auto scar = ReadRows<double>(m.samples[6].get(), d, from, n, 1);
    out.samples.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      ensemble::TrajectorySample& s = out.samples[k];
      s.t_s = t[k];
      s.position_m = Eigen::Vector3d(&position[3 * k]);
      s.orientation = Eigen::Quaterniond(quaternion[4 * k], quaternion[4 * k + 1],
                                         quaternion[4 * k + 2], quaternion[4 * k + 3]);
      s.velocity_m_s = Eigen::Vector3d(&velocity[3 * k]);
      s.angular_velocity_rad_s = Eigen::Vector3d(&angular[3 * k]);
      s.contact = contact[k] != 0;
      s.scar_m = scar[k];
    }
    return out;
  } catch (const Hdf5Failure& failure) {
    throw std::runtime_error("cannot read rock " + std::to_string(rock) + " from " + path_ + ": " +
                             failure.reason);
  }
}

long TrajectoryReader::rocks() const { return static_cast<long>(impl_->rocks); }

}  // namespace talus::io
