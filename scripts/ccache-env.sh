# Sourced by the build scripts from the repository's root: ccache's keys independent of where the
# repository is cloned (paths under the repository made relative, the build directory's path not
# hashed into the debug information's key), so a clone in another folder (CI's) reuses what an
# earlier build on this machine compiled. A caller's own CCACHE_BASEDIR / CCACHE_NOHASHDIR win.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(pwd -P)}"
export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
