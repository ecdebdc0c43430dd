# strata_embed_text(TARGET NAMESPACE FILE...): compiles the text of each FILE into TARGET as
#   std::string_view <NAMESPACE>::embeddedText(std::string_view fileName)
# (the file's name without folders; empty if unknown), regenerated when a file changes. For
# scripts a binary runs wherever it is installed (the report's plotting scripts).
set(_strata_embed_text_script ${CMAKE_CURRENT_LIST_DIR}/StrataEmbedTextScript.cmake)
function(strata_embed_text target ns)
  set(_out ${CMAKE_CURRENT_BINARY_DIR}/${target}_embedded_text.cpp)
  add_custom_command(
    OUTPUT ${_out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${_out} -DNS=${ns} "-DFILES=${ARGN}" -P ${_strata_embed_text_script}
    DEPENDS ${ARGN} ${_strata_embed_text_script}
    COMMENT "Embedding text files into ${target}"
    VERBATIM)
  target_sources(${target} PRIVATE ${_out})
endfunction()
