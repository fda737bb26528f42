"""The lock held around every use of a prepared geometry that threads may share.

GEOS's prepared geometries are not thread-safe (libgeos/geos#825: a prepared polygon's
predicates build and reuse index state on the geometry itself), and shapely releases the
GIL while a predicate runs. A World prepares its obstacles and boundary once and keeps
them, so two threads testing segments in one World (``skyroute.plan`` over a thread
pool) crashed the interpreter with a segmentation fault. Every predicate whose prepared
argument is a World's (the obstacles or the boundary as the first argument, or the
obstacles as an STRtree query's input, which shapely tests through their prepared form)
runs holding :data:`LOCK`, and so does the preparing itself. Geometries made per call
need no lock: unprepared ones are only read.

One re-entrant lock for the process, not one per World: a World pickles as its fields
(a lock does not), and the GIL already lets one thread at a time run Python code, so
searches in threads gain little from testing segments at once.
"""

from __future__ import annotations

import threading

LOCK = threading.RLock()
