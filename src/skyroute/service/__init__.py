"""The REST service over skyroute: an app factory (:func:`skyroute.service.app.create_app`),
settings, bearer-token auth, errors as ``application/problem+json``, one router per
resource and the static viewer. Importing it connects to nothing: the store and the
delivery site are opened on first use."""

from skyroute.lazy import exports as _exports

__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
