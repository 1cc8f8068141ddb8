//! The loops of a shader entry point that end on values read only from uniform buffers and push
//! constants (and constants, and the loop's own counter), found in naga's IR after the pipeline
//! constants are set.
//!
//! lavapipe (Mesa 22.3, Debian 12's) specialises a shader on such values: each time a pipeline
//! whose shader has one is bound, it reads the values, folds them into a copy of the shader and
//! compiles that copy at the next draw, and it never frees the copies. Where the copy's
//! optimisation pays by its own measure it keeps doing so at every bind: the glass's grid of
//! positions per pixel (`supersampled`, its side read from the glass's uniform buffer) cost
//! glass-sphere-real 7 MB of resident memory and a shader compilation at every frame. (Mesa 25,
//! the OpenXR tests' runtime prefix's, keeps one copy per set of values.) A value that ends a
//! loop reaches a shader another way: as a pipeline constant, a flat vertex output or from a
//! storage buffer, none of which lavapipe folds.

use std::collections::HashMap;

use naga::{AddressSpace, Block, Expression, Function, Handle, Module, Statement};

/// Where a value comes from, as far as folding it is concerned; ordered, the later wins when
/// values combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Source {
    /// Literals, constants, pipeline constants, and variables stored only from those (a loop's
    /// counter).
    Fixed,
    /// Uniform buffers and push constants, with the above.
    Uniform,
    /// Anything else: stage inputs, textures, storage buffers, derivatives.
    Varying,
}

/// One loop that ends on uniform values: the function it is in and the uniform globals its end
/// reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UniformLoop {
    /// The function holding the loop (the entry point's name for its own body).
    pub function: String,
    /// The uniform buffers and push constants whose values end it.
    pub globals: Vec<String>,
}

impl std::fmt::Display for UniformLoop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a loop in `{}` ends on values of {}",
            self.function,
            self.globals.join(", ")
        )
    }
}

/// The loops of the entry point whose body is `entry` (named `name`), and of every function it
/// calls, that end on uniform values.
pub fn uniform_loops(module: &Module, name: &str, entry: &Function) -> Vec<UniformLoop> {
    let mut search = Search {
        module,
        found: Vec::new(),
        returns: HashMap::new(),
    };
    // An entry point's arguments are the stage's inputs.
    let arguments = vec![Source::Varying; entry.arguments.len()];
    search.function(name, entry, &arguments);
    let mut found = Vec::new();
    for each in search.found {
        if !found.contains(&each) {
            found.push(each);
        }
    }
    found
}

/// The search through an entry point and its callees.
struct Search<'m> {
    module: &'m Module,
    found: Vec<UniformLoop>,
    /// What each function returns, given where its arguments come from.
    returns: HashMap<(Handle<Function>, Vec<Source>), Source>,
}

/// One function's values: where its arguments and local variables come from.
struct Scope<'f> {
    function: &'f Function,
    arguments: &'f [Source],
    locals: HashMap<Handle<naga::LocalVariable>, Source>,
    /// The calls' results, as evaluated in order.
    results: HashMap<Handle<Expression>, Source>,
}

impl Search<'_> {
    /// Searches `function` called with arguments from `arguments`; returns where its result
    /// comes from.
    fn function(&mut self, name: &str, function: &Function, arguments: &[Source]) -> Source {
        let mut scope = Scope {
            function,
            arguments,
            locals: HashMap::new(),
            results: HashMap::new(),
        };
        // A variable takes the most varying of its initialiser and every value stored in it;
        // stores may read other variables (a counter reads itself), so repeat until settled.
        loop {
            let before = scope.locals.clone();
            for (handle, local) in function.local_variables.iter() {
                let init = local.init.map_or(Source::Fixed, |e| self.source(&scope, e));
                let now = scope.locals.entry(handle).or_insert(Source::Fixed);
                *now = (*now).max(init);
            }
            self.stores(&mut scope, &function.body);
            if scope.locals == before {
                break;
            }
        }
        let mut returned = Source::Fixed;
        self.block(name, &mut scope, &function.body, &mut returned);
        returned
    }

    /// Folds the values `block` stores into its variables into `scope.locals`.
    fn stores(&mut self, scope: &mut Scope, block: &Block) {
        for statement in block.iter() {
            match statement {
                Statement::Store { pointer, value } => {
                    if let Some(local) = local_of(scope.function, *pointer) {
                        let value = self.source(scope, *value);
                        let now = scope.locals.entry(local).or_insert(Source::Fixed);
                        *now = (*now).max(value);
                    }
                }
                Statement::Call {
                    function,
                    arguments,
                    result: Some(result),
                } => {
                    // Calls made before the variables settle are searched again below; here
                    // their results only need to be known where a store reads them.
                    let returns = self.returned(scope, *function, arguments);
                    scope.results.insert(*result, returns);
                }
                _ => {}
            }
            for inner in inner_blocks(statement) {
                self.stores(scope, inner);
            }
        }
    }

    /// Where the result of a call to `callee` with `arguments` comes from, without recording
    /// what the callee holds.
    fn returned(
        &mut self,
        scope: &Scope,
        callee: Handle<Function>,
        arguments: &[Handle<Expression>],
    ) -> Source {
        let handed: Vec<Source> = arguments.iter().map(|&a| self.source(scope, a)).collect();
        if let Some(&known) = self.returns.get(&(callee, handed.clone())) {
            return known;
        }
        let found = self.found.len();
        let function = &self.module.functions[callee];
        let name = function.name.clone().unwrap_or_default();
        let returns = self.function(&name, function, &handed);
        self.found.truncate(found);
        self.returns.insert((callee, handed), returns);
        returns
    }

    /// Searches `block`'s loops and calls; folds what it returns into `returned`.
    fn block(&mut self, name: &str, scope: &mut Scope, block: &Block, returned: &mut Source) {
        for statement in block.iter() {
            match statement {
                Statement::Loop {
                    body,
                    continuing,
                    break_if,
                } => {
                    let mut ends = Vec::new();
                    exits(body, &mut ends);
                    exits(continuing, &mut ends);
                    ends.extend(break_if);
                    for end in ends {
                        if self.source(scope, end) == Source::Uniform {
                            let mut globals = Vec::new();
                            self.uniform_globals(scope, end, &mut globals);
                            globals.sort();
                            globals.dedup();
                            self.found.push(UniformLoop {
                                function: name.to_owned(),
                                globals,
                            });
                        }
                    }
                }
                Statement::Call {
                    function,
                    arguments,
                    result,
                } => {
                    let handed: Vec<Source> =
                        arguments.iter().map(|&a| self.source(scope, a)).collect();
                    let callee = &self.module.functions[*function];
                    let callee_name = callee.name.clone().unwrap_or_default();
                    let returns = self.function(&callee_name, callee, &handed);
                    self.returns.insert((*function, handed), returns);
                    if let Some(result) = result {
                        scope.results.insert(*result, returns);
                    }
                }
                Statement::Return { value: Some(value) } => {
                    *returned = (*returned).max(self.source(scope, *value));
                }
                _ => {}
            }
            for inner in inner_blocks(statement) {
                self.block(name, scope, inner, returned);
            }
        }
    }

    /// Where the value of `handle` comes from.
    fn source(&self, scope: &Scope, handle: Handle<Expression>) -> Source {
        let all = |handles: &mut dyn Iterator<Item = Handle<Expression>>| {
            handles.fold(Source::Fixed, |s, h| s.max(self.source(scope, h)))
        };
        match &scope.function.expressions[handle] {
            Expression::Literal(_)
            | Expression::Constant(_)
            | Expression::Override(_)
            | Expression::ZeroValue(_) => Source::Fixed,
            Expression::FunctionArgument(index) => scope.arguments[*index as usize],
            Expression::GlobalVariable(global) => {
                match self.module.global_variables[*global].space {
                    AddressSpace::Uniform | AddressSpace::PushConstant => Source::Uniform,
                    _ => Source::Varying,
                }
            }
            Expression::LocalVariable(local) => {
                scope.locals.get(local).copied().unwrap_or(Source::Fixed)
            }
            Expression::CallResult(_) => scope
                .results
                .get(&handle)
                .copied()
                .unwrap_or(Source::Varying),
            Expression::Load { pointer } => self.source(scope, *pointer),
            Expression::AccessIndex { base, .. } => self.source(scope, *base),
            Expression::Access { base, index } => all(&mut [*base, *index].into_iter()),
            Expression::Splat { value, .. } => self.source(scope, *value),
            Expression::Swizzle { vector, .. } => self.source(scope, *vector),
            Expression::Compose { components, .. } => all(&mut components.iter().copied()),
            Expression::Unary { expr, .. } => self.source(scope, *expr),
            Expression::Binary { left, right, .. } => all(&mut [*left, *right].into_iter()),
            Expression::Select {
                condition,
                accept,
                reject,
            } => all(&mut [*condition, *accept, *reject].into_iter()),
            Expression::Relational { argument, .. } => self.source(scope, *argument),
            Expression::As { expr, .. } => self.source(scope, *expr),
            Expression::Math {
                arg,
                arg1,
                arg2,
                arg3,
                ..
            } => all(&mut [Some(*arg), *arg1, *arg2, *arg3].into_iter().flatten()),
            _ => Source::Varying,
        }
    }

    /// The names of the uniform globals `handle` reads.
    fn uniform_globals(&self, scope: &Scope, handle: Handle<Expression>, names: &mut Vec<String>) {
        let expression = &scope.function.expressions[handle];
        if let Expression::GlobalVariable(global) = expression {
            let global = &self.module.global_variables[*global];
            if matches!(
                global.space,
                AddressSpace::Uniform | AddressSpace::PushConstant
            ) {
                names.push(format!("`{}`", global.name.clone().unwrap_or_default()));
            }
            return;
        }
        let mut operands = Vec::new();
        match expression {
            Expression::Load { pointer } => operands.push(*pointer),
            Expression::AccessIndex { base, .. }
            | Expression::Splat { value: base, .. }
            | Expression::Swizzle { vector: base, .. }
            | Expression::Unary { expr: base, .. }
            | Expression::Relational { argument: base, .. }
            | Expression::As { expr: base, .. } => operands.push(*base),
            Expression::Access { base, index } => operands.extend([*base, *index]),
            Expression::Compose { components, .. } => operands.extend(components),
            Expression::Binary { left, right, .. } => operands.extend([*left, *right]),
            Expression::Select {
                condition,
                accept,
                reject,
            } => operands.extend([*condition, *accept, *reject]),
            Expression::Math {
                arg,
                arg1,
                arg2,
                arg3,
                ..
            } => operands.extend([Some(*arg), *arg1, *arg2, *arg3].into_iter().flatten()),
            Expression::LocalVariable(_)
            | Expression::FunctionArgument(_)
            | Expression::CallResult(_)
                if self.source(scope, handle) == Source::Uniform =>
            {
                names.push("values handed down from them".to_owned());
            }
            _ => {}
        }
        for operand in operands {
            self.uniform_globals(scope, operand, names);
        }
    }
}

/// The local variable `pointer` names, directly or through an access into it.
fn local_of(
    function: &Function,
    pointer: Handle<Expression>,
) -> Option<Handle<naga::LocalVariable>> {
    match function.expressions[pointer] {
        Expression::LocalVariable(local) => Some(local),
        Expression::Access { base, .. } | Expression::AccessIndex { base, .. } => {
            local_of(function, base)
        }
        _ => None,
    }
}

/// The blocks directly inside `statement`.
fn inner_blocks(statement: &Statement) -> Vec<&Block> {
    match statement {
        Statement::Block(inner) => vec![inner],
        Statement::If { accept, reject, .. } => vec![accept, reject],
        Statement::Switch { cases, .. } => cases.iter().map(|c| &c.body).collect(),
        Statement::Loop {
            body, continuing, ..
        } => vec![body, continuing],
        _ => Vec::new(),
    }
}

/// The conditions of the `if`s in `block` (not inside a loop of its own) one of whose sides
/// leaves the loop (`break`).
fn exits(block: &Block, ends: &mut Vec<Handle<Expression>>) {
    for statement in block.iter() {
        match statement {
            Statement::If {
                condition,
                accept,
                reject,
            } => {
                let breaks = |side: &Block| side.iter().any(|s| matches!(s, Statement::Break));
                if breaks(accept) || breaks(reject) {
                    ends.push(*condition);
                }
                exits(accept, ends);
                exits(reject, ends);
            }
            Statement::Block(inner) => exits(inner, ends),
            _ => {}
        }
    }
}
