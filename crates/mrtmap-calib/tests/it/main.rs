mod pairs;
mod real;
mod synthetic;
