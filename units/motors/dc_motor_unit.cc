namespace linesim::motors {}
