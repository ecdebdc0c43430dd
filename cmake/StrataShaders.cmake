# strata_embed_shaders(TARGET ROOT): embeds every shader program under ROOT (*.comp, *.vert,
# *.frag, *.geom) into TARGET, includes resolved and #line added by strata_shader_embed. The
# depfile it writes lists each included file, so editing an include re-embeds.
function(strata_embed_shaders target root)
  file(GLOB_RECURSE _programs CONFIGURE_DEPENDS RELATIVE ${root}
       ${root}/*.comp ${root}/*.vert ${root}/*.frag ${root}/*.geom)
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
    COMMENT "Embedding shaders from ${root}"
    VERBATIM)
  target_sources(${target} PRIVATE ${_out})
endfunction()
