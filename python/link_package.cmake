# Lays out the build tree's package folder (DST) as an installed package is laid out, with symlinks
# to the source tree, so edits to python/cradle/*.py, configs/ and data/ take effect without a
# rebuild, and the `_cradle` module built into DST finds its data files there (core/resources.h):
#   *.py                 python/cradle/*.py and python/cradle_figures.py
#   configs/             configs/*.yml, configs/curricula/*.yml
#   data/teachmyagent/   data/teachmyagent/*
#   bin/cradle           the CLI (EXE), for the `cradle` command of an editable pip install
#   cradle-resources.txt the marker of a data folder
# pip (setup.py) packages this folder, so it also defines what a pip install holds.
function(link_files pattern dst_dir)
  file(MAKE_DIRECTORY ${dst_dir})
  file(GLOB files ${pattern})
  foreach(f ${files})
    get_filename_component(name ${f} NAME)
    file(CREATE_LINK ${f} ${dst_dir}/${name} SYMBOLIC)
  endforeach()
endfunction()

link_files("${SRC}/python/cradle/*.py" ${DST})
link_files("${SRC}/python/cradle_figures.py" ${DST})
link_files("${SRC}/configs/*.yml" ${DST}/configs)
link_files("${SRC}/configs/curricula/*.yml" ${DST}/configs/curricula)
link_files("${SRC}/data/teachmyagent/*" ${DST}/data/teachmyagent)
file(MAKE_DIRECTORY ${DST}/bin)
file(CREATE_LINK ${EXE} ${DST}/bin/cradle SYMBOLIC)
file(COPY ${SRC}/python/cradle-resources.txt DESTINATION ${DST})
