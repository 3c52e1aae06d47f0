"""The Viewer's exceptions: a request the Viewer cannot carry out."""
from odin_common import OdinError


class ViewerError(OdinError):
    """A request to the Viewer is malformed or names something the Viewer does not have
    (unknown ID, empty mesh, index out of range, NaN pose, bad quaternion, a snapshot name
    outside ``~snapshot_dir``...). The Portal answers it with ``success: false``."""
