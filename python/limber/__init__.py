"""limber for Python: the wire contract (ctypes classes generated from the layout manifest).

The classes in :mod:`limber._layout` have exactly the layout of the Rust structs, so a
sample received through the ``iceoryx2`` Python binding can be read in place::

    from limber import ActArrayData
    state = sample.payload().contents   # an ActArrayData living in shared memory
"""

from ._layout import *  # noqa: F401,F403
from ._layout import LAYOUT_VERSION, STRUCTS  # noqa: F401
