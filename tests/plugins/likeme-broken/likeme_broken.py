"""likeme-broken: a test fixture, a third-party plugin whose import fails as one with a missing dependency does."""

import likeme_dependency_that_is_not_installed  # noqa: F401
