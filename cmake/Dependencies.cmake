# Every third-party dependency comes from a Debian package, found here once.
find_package(PkgConfig REQUIRED)

set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL REQUIRED COMPONENTS EGL)          # OpenGL::EGL only: GL entry points come
                                                       # through our own getproc loader
find_path(GIS_GLCOREARB_H GL/glcorearb.h REQUIRED)     # libgl-dev
# OSMesa (libosmesa6) is loaded with dlopen at run time: no build dependency.

find_package(glm CONFIG REQUIRED)
find_package(nlohmann_json 3 CONFIG REQUIRED)
find_package(TinyGLTF CONFIG REQUIRED)                 # shared lib: never define TINYGLTF_IMPLEMENTATION
pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)    # libstb-dev: image headers read before decoding
find_package(draco CONFIG REQUIRED)                    # libdraco-dev: KHR_draco_mesh_compression
find_package(meshoptimizer CONFIG REQUIRED)            # libmeshoptimizer-dev: EXT_meshopt_compression
pkg_check_modules(LIBZIP REQUIRED IMPORTED_TARGET libzip) # libzip-dev: zipped .gltf uploads
find_package(libjpeg-turbo CONFIG REQUIRED)
find_package(PNG REQUIRED)
find_package(libwebsockets CONFIG REQUIRED)
find_package(Threads REQUIRED)

find_package(OpenImageIO CONFIG REQUIRED)
# Debian 12's OpenImageIO config names /usr/include/opencv4, which does not exist without
# libopencv-dev: drop it so targets that link OIIO configure.
get_target_property(_gis_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_gis_oiio_inc)
    list(REMOVE_ITEM _gis_oiio_inc /usr/include/opencv4)
    set_target_properties(OpenImageIO::OpenImageIO PROPERTIES
        INTERFACE_INCLUDE_DIRECTORIES "${_gis_oiio_inc}" INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "")
endif()

# libwebsockets exports an un-namespaced target: wrap it.
add_library(gis_lws INTERFACE)
target_link_libraries(gis_lws INTERFACE websockets_shared)
add_library(gis::lws ALIAS gis_lws)

if(GIS_BUILD_TESTS)
    find_package(GTest CONFIG REQUIRED)
endif()
