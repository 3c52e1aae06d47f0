"""The GUI package's executables, one module each (``Odin/GUI/scripts/<tool>`` calls
``gui.tools.<tool>.main``): ``problem_info``, ``load_problem``, ``run_path``, ``plan``,
``benchmark``; ``common`` holds what they share (options, the one-line failure boundary).

Each ``main(argv)`` parses its command line into a frozen request, calls the one function
that does the tool's work and prints; it returns the exit status: errors end with status 2
and ONE line on stderr saying what and where (file and line for parsed files). What a
problem holds that Odin does not use is warned about on stderr, once each
("<tool>: warning: ..."), and listed by ``problem_info`` under ``ignored``.
"""
