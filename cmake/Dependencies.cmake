# Every third-party package rocklab uses, found once. Versions are Debian 12's.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)      # Eigen3::Eigen
find_package(OpenMP REQUIRED)                    # OpenMP::OpenMP_CXX
find_package(CLI11 CONFIG REQUIRED)              # CLI11::CLI11
find_package(nlohmann_json 3 REQUIRED)           # nlohmann_json::nlohmann_json
find_package(tomlplusplus REQUIRED)              # tomlplusplus::tomlplusplus
find_package(fmt REQUIRED)                       # fmt::fmt
find_package(assimp REQUIRED)                    # assimp::assimp
# Header-only (needs GMP/MPFR); geometry links it PRIVATE: it never appears in a public header.
find_package(CGAL REQUIRED)                      # CGAL::CGAL (regular triangulation for agglomerates)
# ${OpenCV_LIBS}: plots, frames (imgcodecs), movies (videoio), projectPoints/calibration (calib3d)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs videoio calib3d)
# List the VTK components: without them find_package(VTK) looks for Qt5 and fails.
find_package(VTK 9.1 REQUIRED COMPONENTS IOXML CommonCore CommonDataModel)
# FindHDF5 picks the serial build even when VTK pulled in the OpenMPI one.
find_package(HDF5 REQUIRED COMPONENTS C CXX)     # hdf5::hdf5, hdf5::hdf5_cpp
find_package(ZLIB REQUIRED)                       # ZLIB::ZLIB: crc32 checksums of HDF5 datasets
find_package(Catch2 2 REQUIRED)                  # Catch2::Catch2
# Off-screen GL for render/. Never link OpenGL::GL or libGL with it (STACK.md §3).
find_package(PkgConfig REQUIRED)
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)  # PkgConfig::OSMESA
