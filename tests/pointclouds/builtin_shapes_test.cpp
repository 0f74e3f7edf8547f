#include "pointclouds/builtin_shapes.hpp"

#include <gtest/gtest.h>

#include "common/error.hpp"

namespace talus::pointclouds {
namespace {

Eigen::Vector3d Extent(const Polyhedron& poly) {
  Eigen::Vector3d lo = poly.vertices_m[0], hi = lo;
  for (const auto& v : poly.vertices_m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return hi - lo;
}

BuiltinSpec Spec(const std::string& name, const std::vector<double>& dimensions_m) {
  BuiltinSpec spec;
  spec.name = name;
  spec.dimensions_m = dimensions_m;
  return spec;
}

double Volume(const Polyhedron& poly) { return ComputeMassProperties(poly, 1.0).volume_m3; }

TEST(BuiltinSpec, EveryNameWithItsDimensionsIsValid) {
  std::string why;
  for (const auto& [name, dims] :
       std::vector<std::pair<std::string, std::vector<double>>>{{"box", {1, 2, 3}},
                                                                {"box", {1}},
                                                                {"ellipsoid", {3, 2, 1}},
                                                                {"icosphere", {}},
                                                                {"cylinder", {1, 2}},
                                                                {"disk", {1, 0.2}},
                                                                {"eota111", {}},
                                                                {"eota221", {0.93, 0.93, 0.47}}}) {
    const BuiltinSpec spec = Spec(name, dims);
    EXPECT_TRUE(spec.IsValid(&why)) << name << ": " << why;
    EXPECT_GE(MakeBuiltinShape(spec).vertices_m.size(), 8u) << name;
  }
  EXPECT_FALSE(Spec("boulder", {1}).IsValid(&why));
  EXPECT_NE(why.find("unknown built-in shape 'boulder'; expected one of box"), std::string::npos)
      << why;
  EXPECT_FALSE(Spec("cylinder", {1}).IsValid(&why));
  EXPECT_NE(why.find("diameter, height"), std::string::npos) << why;
  EXPECT_FALSE(Spec("box", {1, -2, 3}).IsValid(&why));
  EXPECT_NE(why.find("positive"), std::string::npos) << why;
  EXPECT_THROW(MakeBuiltinShape(Spec("box", {})), InputError);
}

TEST(MakeBuiltinShape, DimensionsAlongXyz) {
  EXPECT_NEAR((Extent(MakeBuiltinShape(Spec("box", {1, 2, 3}))) - Eigen::Vector3d(1, 2, 3)).norm(),
              0, 1e-15);
  EXPECT_NEAR(
      (Extent(MakeBuiltinShape(Spec("ellipsoid", {3, 2, 1}))) - Eigen::Vector3d(3, 2, 1)).norm(), 0,
      1e-12);
  EXPECT_NEAR(
      (Extent(MakeBuiltinShape(Spec("cylinder", {1, 2}))) - Eigen::Vector3d(1, 1, 2)).norm(), 0,
      1e-12);
  EXPECT_NEAR(Extent(MakeBuiltinShape(Spec("icosphere", {}))).z(), 1, 1e-12);
}

TEST(MakeBuiltinShape, EotaStandardBlocksAreOneCubicMetre) {
  // EOTA test blocks (ETAG 027 / EAD 340059): EOTA111 bounding box 1.122 m, EOTA221 1.414 x 1.414 x
  // 0.707 m, each for 1 m^3; the bevel is chosen so that the volume matches.
  const Polyhedron e111 = MakeBuiltinShape(Spec("eota111", {}));
  EXPECT_NEAR(Volume(e111), 1.0, 1e-9);
  EXPECT_NEAR((Extent(e111) - Eigen::Vector3d::Constant(1.122)).norm(), 0, 1e-12);
  EXPECT_EQ(e111.vertices_m.size(), 24u);
  const Polyhedron e221 = MakeBuiltinShape(Spec("eota221", {}));
  EXPECT_NEAR(Volume(e221), 1.0, 1e-9);
  EXPECT_NEAR((Extent(e221) - Eigen::Vector3d(1.414, 1.414, 0.707)).norm(), 0, 1e-12);

  // Scaled to a volume: same proportions.
  BuiltinSpec big = Spec("eota221", {});
  big.volume_m3 = 8.0;
  EXPECT_NEAR(Volume(MakeBuiltinShape(big)), 8.0, 1e-8);
  EXPECT_NEAR(Extent(MakeBuiltinShape(big)).x(), 2 * 1.414, 1e-12);

  // Given dimensions keep the standard bevel ratio, or take the bevel a volume needs.
  const Polyhedron half = MakeBuiltinShape(Spec("eota111", {0.561}));
  EXPECT_NEAR(Volume(half), 0.125, 1e-9);
  BuiltinSpec chant_sura = Spec("eota221", {0.93, 0.93, 0.47});
  chant_sura.volume_m3 = 780.0 / 2500;
  std::string what;
  EXPECT_NEAR(Volume(MakeBuiltinShape(chant_sura, &what)), 0.312, 1e-9);
  EXPECT_NE(what.find("eota221 0.93 x 0.93 x 0.47 m, bevel"), std::string::npos) << what;
  chant_sura.volume_m3 = 0.5;  // more than the box holds
  EXPECT_THROW(MakeBuiltinShape(chant_sura), InputError);
}

}  // namespace
}  // namespace talus::pointclouds
