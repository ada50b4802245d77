namespace linesim::loader {}
