//! The static cost of one invocation of a shader entry point, read off naga's IR after the
//! pipeline constants are set: its texture fetches, the texels they filter, and its
//! instructions (expressions evaluated, statements and calls), over the entry point and every
//! function it calls.
//!
//! Both sides of a branch count, as on a device that runs a branch's sides masked one after
//! the other (lavapipe does, and a GPU does where the lanes of a wave disagree), except where
//! the condition is a constant: a literal, a pipeline constant, or a constant argument handed
//! down by the caller (the glass pass's entry points call one shading function with constant
//! switches, which every driver's compiler folds). A loop's body counts once. The figures are
//! the same for a shader on every device; multiplied by a pass's invocations they give work
//! that a test can hold to an expectation (render/src/work.rs).

use std::collections::HashMap;

use naga::{
    BinaryOperator, Block, Expression, Function, ImageDimension, Literal, Module, Statement,
    TypeInner, UnaryOperator,
};

/// What one invocation costs.
#[derive(Clone, Copy, Debug, Default)]
pub struct Cost {
    /// Texture fetches (samples and loads).
    pub fetches: u32,
    /// Texels those fetches read: 4 for a filtered 2-D or cube sample, 8 for a filtered 3-D
    /// sample, 1 for a load.
    pub texels: u32,
    /// Expressions evaluated, statements and calls.
    pub instructions: u32,
}

impl Cost {
    fn add(&mut self, other: Cost) {
        self.fetches += other.fetches;
        self.texels += other.texels;
        self.instructions += other.instructions;
    }

    /// The cost as a Rust expression of `vitreous_render::work::ShaderCost`.
    pub fn to_rust(self) -> String {
        format!(
            "crate::work::ShaderCost {{ fetches: {}, texels: {}, instructions: {} }}",
            self.fetches, self.texels, self.instructions
        )
    }
}

/// The constant booleans a caller handed to a function's arguments, by index.
type Known = HashMap<u32, bool>;

/// The cost of one invocation of `function` (an entry point's) of `module`.
pub fn entry_cost(module: &Module, function: &Function) -> Cost {
    block_cost(module, function, &function.body, &Known::new())
}

fn block_cost(module: &Module, function: &Function, block: &Block, known: &Known) -> Cost {
    let mut cost = Cost::default();
    for statement in block.iter() {
        match statement {
            Statement::Emit(range) => {
                for handle in range.clone() {
                    cost.add(expression_cost(module, function, handle));
                }
            }
            Statement::Block(inner) => cost.add(block_cost(module, function, inner, known)),
            Statement::If {
                condition,
                accept,
                reject,
            } => {
                cost.instructions += 1;
                match truth(module, function, *condition, known) {
                    Some(true) => cost.add(block_cost(module, function, accept, known)),
                    Some(false) => cost.add(block_cost(module, function, reject, known)),
                    None => {
                        cost.add(block_cost(module, function, accept, known));
                        cost.add(block_cost(module, function, reject, known));
                    }
                }
            }
            Statement::Switch { cases, .. } => {
                cost.instructions += 1;
                for case in cases {
                    cost.add(block_cost(module, function, &case.body, known));
                }
            }
            Statement::Loop {
                body, continuing, ..
            } => {
                cost.instructions += 1;
                cost.add(block_cost(module, function, body, known));
                cost.add(block_cost(module, function, continuing, known));
            }
            Statement::Call {
                function: callee,
                arguments,
                ..
            } => {
                cost.instructions += 1;
                let handed: Known = arguments
                    .iter()
                    .enumerate()
                    .filter_map(|(i, &argument)| {
                        truth(module, function, argument, known).map(|value| (i as u32, value))
                    })
                    .collect();
                let callee = &module.functions[*callee];
                cost.add(block_cost(module, callee, &callee.body, &handed));
            }
            _ => cost.instructions += 1,
        }
    }
    cost
}

/// One expression's cost: a fetch with its texels, or one instruction (constants, arguments
/// and variables' addresses cost nothing).
fn expression_cost(module: &Module, function: &Function, handle: naga::Handle<Expression>) -> Cost {
    match &function.expressions[handle] {
        Expression::ImageSample { image, .. } => {
            let filtered = match image_dimension(module, function, *image) {
                Some(ImageDimension::D3) => 8,
                _ => 4,
            };
            Cost {
                fetches: 1,
                texels: filtered,
                instructions: 1,
            }
        }
        Expression::ImageLoad { .. } => Cost {
            fetches: 1,
            texels: 1,
            instructions: 1,
        },
        Expression::Literal(_)
        | Expression::Constant(_)
        | Expression::Override(_)
        | Expression::FunctionArgument(_)
        | Expression::GlobalVariable(_)
        | Expression::LocalVariable(_) => Cost::default(),
        _ => Cost {
            instructions: 1,
            ..Cost::default()
        },
    }
}

/// The dimension of the image an expression names, when it is a global texture.
fn image_dimension(
    module: &Module,
    function: &Function,
    image: naga::Handle<Expression>,
) -> Option<ImageDimension> {
    let Expression::GlobalVariable(global) = function.expressions[image] else {
        return None;
    };
    match module.types[module.global_variables[global].ty].inner {
        TypeInner::Image { dim, .. } => Some(dim),
        _ => None,
    }
}

/// The value of a boolean expression when it is a constant (a literal, a module constant, a
/// set pipeline constant, an argument the caller handed a constant, or `!`, `&&`, `||` of
/// those); `None` otherwise.
fn truth(
    module: &Module,
    function: &Function,
    handle: naga::Handle<Expression>,
    known: &Known,
) -> Option<bool> {
    match &function.expressions[handle] {
        Expression::Literal(Literal::Bool(value)) => Some(*value),
        Expression::FunctionArgument(index) => known.get(index).copied(),
        Expression::Constant(constant) => {
            match module.global_expressions[module.constants[*constant].init] {
                Expression::Literal(Literal::Bool(value)) => Some(value),
                _ => None,
            }
        }
        Expression::Unary {
            op: UnaryOperator::LogicalNot,
            expr,
        } => truth(module, function, *expr, known).map(|value| !value),
        Expression::Binary { op, left, right } => {
            let (a, b) = (
                truth(module, function, *left, known),
                truth(module, function, *right, known),
            );
            match op {
                BinaryOperator::LogicalAnd => match (a, b) {
                    (Some(false), _) | (_, Some(false)) => Some(false),
                    (Some(true), Some(true)) => Some(true),
                    _ => None,
                },
                BinaryOperator::LogicalOr => match (a, b) {
                    (Some(true), _) | (_, Some(true)) => Some(true),
                    (Some(false), Some(false)) => Some(false),
                    _ => None,
                },
                _ => None,
            }
        }
        _ => None,
    }
}
