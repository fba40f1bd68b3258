#!/bin/bash
# examples/remoteio/run.sh PLCRT [INI]: the remote I/O example. Makes the
# serial line (a socat pseudo-terminal pair under build/remoteio), starts
# the two modules (modules.py) and then plcrt in the foreground; when
# plcrt stops (Ctrl-C), the modules and the line stop too. The panel
# listens on port ${REMOTEIO_PANEL_PORT:-5020} (the INI's [modbus_io.panel]).
set -u
plcrt=$1
ini=${2:-examples/remoteio/remoteio.ini}
mkdir -p build/remoteio
socat pty,raw,echo=0,link=build/remoteio/tty-plc pty,raw,echo=0,link=build/remoteio/tty-mod &
line=$!
for _ in $(seq 100); do [ -e build/remoteio/tty-mod ] && [ -e build/remoteio/tty-plc ] && break; sleep 0.05; done
panel=${REMOTEIO_PANEL_PORT:-5020}
python3 examples/remoteio/modules.py build/remoteio/tty-mod "$panel" &
modules=$!
for _ in $(seq 100); do (exec 3<>/dev/tcp/127.0.0.1/$panel) 2>/dev/null && break; sleep 0.1; done
trap 'kill $modules $line 2>/dev/null; wait $modules $line 2>/dev/null' EXIT
mk/run_fg.sh "$plcrt" -c "$ini"
