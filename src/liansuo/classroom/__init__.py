"""The classroom, between the simulation and its front ends: roles and passwords, exercises, a trainee's answers,
the assessment, its unsafe-action rules, score and report, and the snapshot the classroom server sends."""
