"""Every figure of the package, one module per subject; nothing is imported here (results load them lazily).

* :mod:`~stickslip.plots.style` — the common look, Axes/Figure makers, display units and colours;
* :mod:`~stickslip.plots.steady` — the steady friction curve (Figs 1, 4) and a protocol's staircase;
* :mod:`~stickslip.plots.cycles` — the quasi-static cycle: sigma(t), V(t), Nc/Nc0(t), Fig 2;
* :mod:`~stickslip.plots.transient` — runs of the time-dependent bond model (and the report's Eq 1 figure);
* :mod:`~stickslip.plots.rsf` — rate-and-state runs, records, fits and stability;
* :mod:`~stickslip.plots.traces` — the analysis of a measured (or simulated) trace;
* :mod:`~stickslip.plots.fits` — steady and stick fits, residuals, the posterior's corner plot;
* :mod:`~stickslip.plots.sweeps` — a sweep's phase diagram (2-D) or its results against one key (1-D);
* :mod:`~stickslip.plots.export` — saving figures (PNG, SVG) and reading every drawn curve back as CSV;
* :mod:`~stickslip.plots.compare` — the bond model beside rate-and-state (``stickslip compare``);
* ``run`` and ``overlay`` — a run of any model, and several models' runs of one protocol.

Figures are built on :class:`matplotlib.figure.Figure`, never through pyplot: nothing here opens a window,
calls ``show()`` or touches global state.  Every ``plot_*`` function takes ``ax=None`` (a new Figure then) and
returns its Axes; ``figure_*`` (and ``*_figure``) functions build a whole, possibly multi-panel, Figure.
"""
