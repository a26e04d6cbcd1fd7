# ghostfx_add_library(<name> SOURCES <files...> [PUBLIC <deps...>] [PRIVATE <deps...>])
# One ghostfx library: target ghostfx_<name>, alias and export name ghostfx::<name>, headers in
# <dir>/include (installed as they are), shared by default, common warnings, installed into the
# ghostfxTargets export set behind find_package(ghostfx).
function(ghostfx_add_library name)
    cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
    set(target ghostfx_${name})
    add_library(${target} ${ARG_SOURCES})
    add_library(ghostfx::${name} ALIAS ${target})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME ${target})
    target_include_directories(${target} PUBLIC
        $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
        $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE} ghostfx_options)
    install(TARGETS ${target} EXPORT ghostfxTargets
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
            LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
    install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
