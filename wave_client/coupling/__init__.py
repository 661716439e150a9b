"""The coupling client: drives a `WaveModel` against the SPH server over the wavesph protocol.

    from wave_client.coupling import couple, CouplingOptions
    report = couple("tcp://127.0.0.1:8766", model, CouplingOptions(window=0.05), run_id="r1")

`core` is sans-I/O (testable without a server), `transport` moves frames over WebSocket or TCP,
`runner` is the loop with timeouts, error frames, progress bar and the CSV gauge log.
"""

from wave_client.coupling.core import (CouplingCore, CouplingError, CouplingOptions,
                                       ServerEnded, WindowRecord)
from wave_client.coupling.runner import (CouplingReport, CouplingTimeout, GaugeLog, ServerError,
                                         couple, run_coupling)
from wave_client.coupling.transport import parse_url

__all__ = ["CouplingCore", "CouplingError", "CouplingOptions", "CouplingReport", "CouplingTimeout",
           "GaugeLog", "ServerEnded", "ServerError", "WindowRecord", "couple", "parse_url", "run_coupling"]
