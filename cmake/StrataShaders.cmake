# strata_embed_shaders(TARGET ROOT DIR...): embeds every shader program (*.comp, *.vert, *.frag,
# *.geom) under ROOT/DIR... into TARGET, each named by its path from ROOT (e.g.
# "sim/shaders/fv_face.comp"), includes resolved and #line added by strata_shader_embed. The
# depfile it writes lists each included file, so editing an include re-embeds.
function(strata_embed_shaders target root)
  set(_programs)
  foreach(dir IN LISTS ARGN)
    file(GLOB_RECURSE _found CONFIGURE_DEPENDS RELATIVE ${root}
         ${root}/${dir}/*.comp ${root}/${dir}/*.vert ${root}/${dir}/*.frag ${root}/${dir}/*.geom)
    list(APPEND _programs ${_found})
  endforeach()
  list(SORT _programs)
  set(_out ${CMAKE_CURRENT_BINARY_DIR}/embedded_shaders.cpp)
  set(_dep ${CMAKE_CURRENT_BINARY_DIR}/embedded_shaders.d)
  set(_abs)
  foreach(p IN LISTS _programs)
    list(APPEND _abs ${root}/${p})
  endforeach()
  add_custom_command(
    OUTPUT ${_out}
    COMMAND strata_shader_embed ${root} ${_out} ${_dep} ${_programs}
    DEPENDS strata_shader_embed ${_abs}
    DEPFILE ${_dep}
    COMMENT "Embedding shaders"
    VERBATIM)
  target_sources(${target} PRIVATE ${_out})
endfunction()
