"""The engine kept current: it re-runs the recovery when the settings change, and only then."""

import time

import aarecovery

from .settings import RecoverySettings

__all__ = ["LiveRecovery"]


class LiveRecovery:
    """An engine, the pair loaded in it, the settings the user wants and the ones R was made with.

    Parameters
    ----------
    engine : aarecovery.Engine
        A GL engine in the window's context (the app owns and releases it).
    messages : MessageLog
        Where a refused setting is reported.
    maps_wanted : callable
        ``maps_wanted() -> bool``: the view shows a map now, so a run must keep the maps.
    settings : RecoverySettings, optional
        The first settings; the defaults when None.

    Attributes
    ----------
    settings : RecoverySettings
        What the widgets ask for.
    pair : LoadedPair or None
        The pair in the engine and on screen.
    computed : tuple or None
        ``(settings, with maps)`` of the R in the engine's textures; None before the first
        run on a pair.
    recoveries : int
        How many times the recovery ran.
    summary : aarecovery.RecoverySummary or None
        What the shown R repaired (``aarecovery.summarize_recovery``), once the settings have
        rested :data:`SUMMARY_DELAY` seconds: it reads R back, which a slider drag should not
        pay on every frame.
    """

    #: Seconds a result must stay shown before its summary is made.
    SUMMARY_DELAY = 0.3

    def __init__(self, engine, messages, maps_wanted, settings=None):
        self.engine = engine
        self.messages = messages
        self.maps_wanted = maps_wanted
        self.settings = settings or RecoverySettings.defaults()
        self.pair = None
        self.computed = None
        self.recoveries = 0
        #: aarecovery.check_order's verdict on the pair shown (None before the first pair).
        self.order = None
        self.summary = None
        self._summarized = None
        self._computed_at = 0.0

    def load(self, pair):
        """Load `pair` into the engine and show it from the next update.

        Raises
        ------
        aarecovery.InputError
            When the engine refuses the pair; call :meth:`restore_shown_pair` then.
        """
        self.engine.set_images(pair.original, pair.filtered, quantization=pair.quantization)
        self.pair = pair
        self.computed = None
        self.summary = self._summarized = None
        self.order = aarecovery.check_order(pair.original, pair.filtered)

    def restore_shown_pair(self):
        """Put the shown pair back into the engine after a pair failed to load."""
        if self.pair is None:
            return
        try:
            self.engine.set_images(self.pair.original, self.pair.filtered, quantization=self.pair.quantization)
        except aarecovery.InputError as error:  # the pair loaded before, so this is unexpected
            self.messages.error(f"could not restore the previous images: {error}")
            self.pair = None
        self.computed = None

    def update(self):
        """Run the recovery if the settings (or the need for maps) changed since the last run.

        Returns
        -------
        bool
            True when the recovery ran.
        """
        if self.pair is None:
            return False
        maps = self.maps_wanted()
        if self.computed is not None and self.computed[0] == self.settings and (self.computed[1] or not maps):
            return False
        try:
            self.engine.compute(maps=maps, **self.settings.compute_arguments())
        except aarecovery.InputError as error:
            self.messages.error(str(error))
            self.settings = self.computed[0] if self.computed else RecoverySettings.defaults()
            return False
        self.computed = (self.settings, maps)
        self._computed_at = time.perf_counter()
        self.recoveries += 1
        return True

    def refresh_summary(self, now=None):
        """Summarize the shown R once it has been shown :data:`SUMMARY_DELAY` seconds.

        Returns
        -------
        bool
            True when a new summary was made.
        """
        now = time.perf_counter() if now is None else now
        if self.computed is None or self.computed == self._summarized:
            return False
        if now - self._computed_at < self.SUMMARY_DELAY:
            return False
        result = self.engine.result()
        self.summary = aarecovery.summarize_recovery(self.engine.last_plan, self.pair.original, self.pair.filtered,
                                                     result)
        self._summarized = self.computed
        return True
