#include "io/trajectory_file.hpp"

#include <hdf5.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
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

template <class T>
void Dataset(hid_t group, const char* name, hid_t type, const std::vector<T>& data, hsize_t rows,
             hsize_t columns) {
  const hsize_t dims[2] = {rows, columns};
  const int rank = columns == 1 ? 1 : 2;
  const Handle space(Check(H5Screate_simple(rank, dims, nullptr), "create a dataspace"), H5Sclose);
  const Handle properties = UntimedCreation(H5P_DATASET_CREATE);
  if (rows > 0) {
    const hsize_t chunk[2] = {std::min<hsize_t>(rows, 4096), columns};
    Check(H5Pset_chunk(properties.get(), rank, chunk), "set chunks");
    Check(H5Pset_shuffle(properties.get()), "set shuffle");
    Check(H5Pset_deflate(properties.get(), 4), "set deflate");
  }
  Handle set(
      Check(H5Dcreate2(group, name, type, space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
            "create a dataset"),
      H5Dclose);
  if (rows > 0)
    Check(H5Dwrite(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), "write data");
  // Closing writes the chunks still in the cache: a full disk shows here.
  if (!set.Close()) Fail("write data");
}

// Closes a file that is being abandoned (its temporary file is about to be removed) without
// writing what HDF5 still holds for it to disk: its descriptor is first pointed at an anonymous
// memory file, and a soft file-size limit is lifted meanwhile. HDF5 cannot drop a file whose close
// fails: it keeps a half-freed file that crashes it at exit.
void Abandon(Handle& file) {
  void* vfd = nullptr;
  if (file.get() < 0 || H5Fget_vfd_handle(file.get(), H5P_DEFAULT, &vfd) < 0 || !vfd) {
    file.Close();
    return;
  }
  const int fd = *static_cast<int*>(vfd);  // the default (sec2) driver's descriptor
  if (const int memory = ::memfd_create("talus-abandoned.h5", MFD_CLOEXEC); memory >= 0) {
    ::dup2(memory, fd);
    ::close(memory);
  }
  rlimit limit{};
  const bool lift = ::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != limit.rlim_max;
  if (lift) {
    const rlimit lifted{limit.rlim_max, limit.rlim_max};
    ::setrlimit(RLIMIT_FSIZE, &lifted);
  }
  file.Close();
  if (lift) ::setrlimit(RLIMIT_FSIZE, &limit);
}

}  // namespace

struct TrajectoryWriter::Impl {
  Handle file;  // declared first: closed last
  Handle rocks;
  double mass_kg = 0;
  std::vector<double> inertia;
  bool committed = false;

  ~Impl() {
    if (committed) return;
    rocks.Close();
    Abandon(file);
  }
};

TrajectoryWriter::TrajectoryWriter(const std::string& path, const RockShape& rock) : file_(path) {
  SilenceHdf5();
  impl_ = std::make_unique<Impl>();
  impl_->mass_kg = rock.mass_kg;
  impl_->inertia = {rock.inertia_kg_m2.x(), rock.inertia_kg_m2.y(), rock.inertia_kg_m2.z()};
  try {
    impl_->file =
        Handle(Check(H5Fcreate(file_.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                     "create the file"),
               H5Fclose);
    impl_->rocks = CreateGroup(impl_->file.get(), "/rocks");
    Attribute(impl_->file.get(), "mass_kg", {impl_->mass_kg});
    Attribute(impl_->file.get(), "principal_inertia_kg_m2", impl_->inertia);
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
    stored.principal_inertia_kg_m2 = Eigen::Vector3d(impl_->inertia.data());
  }
  stored.samples = rock.trajectory;
  Write(rock.rock, stored);
}

void TrajectoryWriter::Write(long rock, const StoredTrajectory& stored) {
  if (!impl_) throw std::logic_error("TrajectoryWriter::Write after a failure or Commit");
  SilenceHdf5();
  const auto& samples = stored.samples;
  const hsize_t n = samples.size();
  std::vector<double> t, position, quaternion, velocity, angular, scar;
  std::vector<std::uint8_t> contact;
  for (const ensemble::TrajectorySample& s : samples) {
    t.push_back(s.t_s);
    position.insert(position.end(), {s.position_m.x(), s.position_m.y(), s.position_m.z()});
    quaternion.insert(quaternion.end(),
                      {s.orientation.w(), s.orientation.x(), s.orientation.y(), s.orientation.z()});
    velocity.insert(velocity.end(), {s.velocity_m_s.x(), s.velocity_m_s.y(), s.velocity_m_s.z()});
    angular.insert(angular.end(), {s.angular_velocity_rad_s.x(), s.angular_velocity_rad_s.y(),
                                   s.angular_velocity_rad_s.z()});
    contact.push_back(s.contact ? 1 : 0);
    scar.push_back(s.scar_m);
  }
  try {
    Handle group = CreateGroup(impl_->rocks.get(), std::to_string(rock).c_str());
    const Eigen::Vector3d& inertia = stored.principal_inertia_kg_m2;
    Attribute(group.get(), "mass_kg", {stored.mass_kg});
    Attribute(group.get(), "principal_inertia_kg_m2", {inertia.x(), inertia.y(), inertia.z()});
    const hid_t d = H5T_NATIVE_DOUBLE;
    Dataset(group.get(), "t", d, t, n, 1);
    Dataset(group.get(), "position", d, position, n, 3);
    Dataset(group.get(), "quaternion", d, quaternion, n, 4);
    Dataset(group.get(), "velocity", d, velocity, n, 3);
    Dataset(group.get(), "angular_velocity", d, angular, n, 3);
    Dataset(group.get(), "contact", H5T_NATIVE_UINT8, contact, n, 1);
    Dataset(group.get(), "scar", d, scar, n, 1);
    if (!group.Close()) Fail("close a group");
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
    Check(H5Fflush(impl_->file.get(), H5F_SCOPE_GLOBAL), "flush the file");
    if (!impl_->rocks.Close()) Fail("close a group");
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

// Reads a whole attribute or dataset of doubles (or bytes) of `n` values.
template <class T>
std::vector<T> ReadValues(hid_t object, const char* name, hid_t type, bool attribute,
                          hsize_t per_row, hsize_t* rows) {
  Handle item = attribute ? Handle(Check(H5Aopen(object, name, H5P_DEFAULT), name), H5Aclose)
                          : Handle(Check(H5Dopen2(object, name, H5P_DEFAULT), name), H5Dclose);
  Handle space(Check(attribute ? H5Aget_space(item.get()) : H5Dget_space(item.get()), name),
               H5Sclose);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0 || static_cast<hsize_t>(n) % per_row != 0) Fail(name);
  if (rows) *rows = static_cast<hsize_t>(n) / per_row;
  std::vector<T> values(static_cast<std::size_t>(n));
  if (n > 0)
    Check(attribute ? H5Aread(item.get(), type, values.data())
                    : H5Dread(item.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()),
          name);
  return values;
}

}  // namespace

struct TrajectoryReader::Impl {
  Handle file;
};

TrajectoryReader::TrajectoryReader(const std::string& path) : path_(path) {
  SilenceHdf5();
  impl_ = std::make_unique<Impl>();
  try {
    impl_->file = Handle(Check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open the file"),
                         H5Fclose);
  } catch (const Hdf5Failure& failure) {
    throw std::runtime_error("cannot read " + path + ": " + failure.reason);
  }
}

TrajectoryReader::~TrajectoryReader() = default;

StoredTrajectory TrajectoryReader::Read(long rock) const {
  SilenceHdf5();
  const std::string name = "/rocks/" + std::to_string(rock);
  try {
    const Handle group(
        Check(H5Gopen2(impl_->file.get(), name.c_str(), H5P_DEFAULT), "no such rock"), H5Gclose);
    const hid_t g = group.get();
    const hid_t d = H5T_NATIVE_DOUBLE;
    StoredTrajectory out;
    const auto mass = ReadValues<double>(g, "mass_kg", d, true, 1, nullptr);
    const auto inertia = ReadValues<double>(g, "principal_inertia_kg_m2", d, true, 3, nullptr);
    if (mass.size() != 1 || inertia.size() != 3) Fail("rock attributes");
    out.mass_kg = mass[0];
    out.principal_inertia_kg_m2 = Eigen::Vector3d(inertia.data());
    hsize_t n = 0, rows = 0;
    const auto t = ReadValues<double>(g, "t", d, false, 1, &n);
    const auto check = [&](hsize_t r) {
      if (r != n) Fail("datasets of different lengths");
    };
    const auto position = ReadValues<double>(g, "position", d, false, 3, &rows);
    check(rows);
    const auto quaternion = ReadValues<double>(g, "quaternion", d, false, 4, &rows);
    check(rows);
    const auto velocity = ReadValues<double>(g, "velocity", d, false, 3, &rows);
    check(rows);
    const auto angular = ReadValues<double>(g, "angular_velocity", d, false, 3, &rows);
    check(rows);
    const auto contact = ReadValues<std::uint8_t>(g, "contact", H5T_NATIVE_UINT8, false, 1, &rows);
    check(rows);
    const auto scar = ReadValues<double>(g, "scar", d, false, 1, &rows);
    check(rows);
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

}  // namespace talus::io
