#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Runs a command that renders. Debian's VTK renders through GLX only, so it needs an X display: the one in
# DISPLAY when there is one, else a virtual server of its own from xvfb-run. Utilities/setup.sh runs the demo
# and the whole test suite through this script, so that all their tests share one server.
#
# -noreset: an X server resets when its last client disconnects, and refuses connections while it does; a
# program that closes one render window and opens another (the examples write two images) then failed now
# and then with "bad X server connection".
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
exec xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" "$@"
