#include "pointclouds/pcl_files.hpp"

#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

extern "C" int TalusLoadPclFile(const char* path, bool pcd, pcl::PCLPointCloud2* blob) {
  return pcd ? pcl::io::loadPCDFile(path, *blob) : pcl::io::loadPLYFile(path, *blob);
}
