#include "io/trajectory_file.hpp"

#include <H5Cpp.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace talus::io {

struct TrajectoryWriter::Impl {
  H5::H5File file;
  H5::Group rocks;
  double mass_kg = 0;
  std::vector<double> inertia;
};

namespace {

void Attribute(H5::H5Object& object, const char* name, const std::vector<double>& values) {
  const hsize_t n = values.size();
  H5::DataSpace space(1, &n);
  H5::Attribute a = object.createAttribute(name, H5::PredType::NATIVE_DOUBLE, space);
  a.write(H5::PredType::NATIVE_DOUBLE, values.data());
}

template <class T>
void Dataset(H5::Group& group, const char* name, const H5::PredType& type,
             const std::vector<T>& data, hsize_t rows, hsize_t columns) {
  const hsize_t dims[2] = {rows, columns};
  const int rank = columns == 1 ? 1 : 2;
  H5::DataSpace space(rank, dims);
  H5::DSetCreatPropList properties;
  if (rows > 0) {
    const hsize_t chunk[2] = {std::min<hsize_t>(rows, 4096), columns};
    properties.setChunk(rank, chunk);
    properties.setShuffle();
    properties.setDeflate(4);
  }
  H5::DataSet set = group.createDataSet(name, type, space, properties);
  if (rows > 0) set.write(data.data(), type);
}

}  // namespace

TrajectoryWriter::TrajectoryWriter(const std::string& path, const RockShape& rock) : file_(path) {
  H5::Exception::dontPrint();
  impl_ = std::make_unique<Impl>();
  impl_->mass_kg = rock.mass_kg;
  impl_->inertia = {rock.inertia_kg_m2.x(), rock.inertia_kg_m2.y(), rock.inertia_kg_m2.z()};
  try {
    impl_->file = H5::H5File(file_.temp_path(), H5F_ACC_TRUNC);
    impl_->rocks = impl_->file.createGroup("/rocks");
    Attribute(impl_->file, "mass_kg", {impl_->mass_kg});
    Attribute(impl_->file, "principal_inertia_kg_m2", impl_->inertia);
  } catch (const H5::Exception& e) {
    throw std::runtime_error("cannot create " + file_.temp_path() + ": " + e.getDetailMsg());
  }
}

TrajectoryWriter::~TrajectoryWriter() = default;

void TrajectoryWriter::Write(const ensemble::RockOutcome& rock) {
  const auto& samples = rock.trajectory;
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
    H5::Group group = impl_->rocks.createGroup(std::to_string(rock.rock));
    Attribute(group, "mass_kg", {impl_->mass_kg});
    Attribute(group, "principal_inertia_kg_m2", impl_->inertia);
    const auto& d = H5::PredType::NATIVE_DOUBLE;
    Dataset(group, "t", d, t, n, 1);
    Dataset(group, "position", d, position, n, 3);
    Dataset(group, "quaternion", d, quaternion, n, 4);
    Dataset(group, "velocity", d, velocity, n, 3);
    Dataset(group, "angular_velocity", d, angular, n, 3);
    Dataset(group, "contact", H5::PredType::NATIVE_UINT8, contact, n, 1);
    Dataset(group, "scar", d, scar, n, 1);
  } catch (const H5::Exception& e) {
    throw std::runtime_error("cannot write rock " + std::to_string(rock.rock) + " to " +
                             file_.temp_path() + ": " + e.getDetailMsg());
  }
}

void TrajectoryWriter::Commit() {
  try {
    impl_->rocks.close();
    impl_->file.close();
  } catch (const H5::Exception& e) {
    throw std::runtime_error("cannot close " + file_.temp_path() + ": " + e.getDetailMsg());
  }
  file_.Commit();
}

}  // namespace talus::io
