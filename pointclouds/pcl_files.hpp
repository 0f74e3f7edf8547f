#pragma once
// PCL's PCD and PLY readers, built as the module talus_pcl_files (pcl_files.cpp) that
// point_cloud.cpp loads the first time it reads such a file. Debian's libpcl_io links VTK (for
// PCL's VTK and image formats); linked into the program, VTK's libraries would load at the start
// of every talus call, whatever the verb (bench/README.md, "Start-up and linking").

#include <pcl/PCLPointCloud2.h>

// Reads a PCD (pcd true) or PLY file into blob. Returns PCL's status, negative when PCL could not
// read the file; PCL's exceptions pass through.
extern "C" int TalusLoadPclFile(const char* path, bool pcd, pcl::PCLPointCloud2* blob);
