"""Whole jobs shared by the command line and the web app.

A pipeline runs a mission from its validated description to its output set:
:func:`~fm2uav.pipeline.run.run_mission` (a mission file: world, FM² route,
autopilot mission, exports, report), :func:`~fm2uav.pipeline.outputs.plan_outputs`
(the output set of a plan) and the summary rows both front ends show
(:mod:`fm2uav.pipeline.rows`). Pipelines report their stages through
:mod:`fm2uav.progress` and never print.
"""
